"""The one CSV writer of the benchmark scripts: a list of dict rows, header from the
first row (or ``fields``)."""
from __future__ import annotations

import csv
from pathlib import Path


def write_rows(path: Path, rows: list[dict], fields: list[str] | None = None) -> None:
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields or list(rows[0]))
        w.writeheader()
        w.writerows(rows)
