import sys

from volerr.cli import main

sys.exit(main())
