"""`python -m wavesph ...`: the `wavesph` console script without installing it."""

from wavesph.cli import main

raise SystemExit(main())
