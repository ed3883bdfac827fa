"""``python -m slidernet.paper OUT_DIR [--quick] [--no-progress]``."""

import sys

from slidernet.paper.reproduction import main

sys.exit(main())
