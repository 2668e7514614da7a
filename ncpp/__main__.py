import sys

from ncpp.cli import main

sys.exit(main())
