import sys

from randvib.cli import main

sys.exit(main())
