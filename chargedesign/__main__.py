import sys

from chargedesign.cli import main

sys.exit(main())
