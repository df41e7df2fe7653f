"""``python -m mcengine_blender.cli``: the same as the ``mcengine`` command."""
import sys

from . import main

sys.exit(main())
