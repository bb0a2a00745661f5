"""The report's three cube files shipped in params/clouds/, with their particle totals."""
from pathlib import Path

PARAMS = Path(__file__).resolve().parents[2] / "params" / "clouds"
TABLES = {"4.2": PARAMS / "table_4_2.awn", "4.3": PARAMS / "table_4_3.awn",
          "4.4": PARAMS / "table_4_4.awn"}
TOTALS = {"4.2": 2000, "4.3": 554, "4.4": 615}
