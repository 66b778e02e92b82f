import sys

from frontier_marl.cli.main import main

sys.exit(main())
