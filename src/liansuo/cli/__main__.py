"""``python -m liansuo.cli``: the same as the ``liansuo`` command."""

import sys

from liansuo.cli.main import main

sys.exit(main())
