import sys

from frontier_marl.cli import main

sys.exit(main())
