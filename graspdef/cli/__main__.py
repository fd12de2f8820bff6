"""``python -m graspdef.cli ...`` = ``graspdef ...``."""
import sys

from . import main

sys.exit(main())
