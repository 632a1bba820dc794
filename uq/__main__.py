import sys

from uq.cli import main

sys.exit(main())
