"""``python -m otonav``: the command-line interface."""

from otonav.cli import main

raise SystemExit(main())
