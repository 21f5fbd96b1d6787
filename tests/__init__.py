"""hiper's tests, in folders that mirror hiper_cli's packages; helpers stay here."""

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
# the realistic worlds (../shared/worlds beside the checkout, or HIPER_WORLDS)
WORLDS = Path(os.environ.get("HIPER_WORLDS", "") or REPO_ROOT.parent / "shared" / "worlds")
