"""``python -m liansuo``: the ``liansuo`` command."""

from liansuo.cli.main import main

raise SystemExit(main())
