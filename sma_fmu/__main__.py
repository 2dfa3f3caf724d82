"""``python -m sma_fmu`` runs the command line."""
from sma_fmu.cli import main

raise SystemExit(main())
