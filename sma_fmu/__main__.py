"""``python -m sma_fmu`` runs the command line."""
from .cli import main

raise SystemExit(main())
