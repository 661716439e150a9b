"""`python -m wavesph_cli ...`: the `wavesph` console script without installing it."""

from wavesph_cli import main

raise SystemExit(main())
