"""Shared by the execution benchmarks (closed_loop.py, paraphrases.py): their JSON report."""
from __future__ import annotations

import json
import os
import platform
from pathlib import Path

import pandas as pd
import torch


def write_report(path: str | Path, table: pd.DataFrame, summary: pd.DataFrame, seconds: float, **fields) -> None:
    """``fields`` (what was run), the timing and the machine, the summary and every episode, as JSON."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({
        **fields, "seconds": seconds, "seconds_per_episode": seconds / len(table),
        "threads": torch.get_num_threads(), "machine": platform.processor() or platform.machine(),
        "load_average": os.getloadavg()[0],
        "summary": summary.reset_index().to_dict(orient="records"),
        "episodes": table.to_dict(orient="records")}, indent=1))
    print(f"\nwritten to {out}")
