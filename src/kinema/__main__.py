"""``python -m kinema`` runs the CLI."""

from __future__ import annotations

import sys

from kinema.cli.main import main

sys.exit(main())
