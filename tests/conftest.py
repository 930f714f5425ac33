import sys
from pathlib import Path

# tests/helpers.py is imported as a plain module
sys.path.insert(0, str(Path(__file__).resolve().parent))

from chi2 import alpha  # noqa: E402, F401  (the Šidák-corrected significance fixture, for every test)
