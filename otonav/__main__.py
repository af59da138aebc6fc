"""``python -m otonav``: the command-line interface."""

from otonav._entry import main

raise SystemExit(main())
