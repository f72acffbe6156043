"""``python -m mitsuba_birefringent``: the command ``mitsuba-birefringent`` (:mod:`.cli`)."""

import sys

from mitsuba_birefringent.cli import main

sys.exit(main())
