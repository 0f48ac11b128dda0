"""The departures table (pgae_lite/runs/departures.py): complete, and each effect read from its result file."""
from dataclasses import asdict

import pytest

from pgae_lite.config import BOOK, PAPER
from pgae_lite.runs import departures
from pgae_lite.runs.departures import DEPARTURES, NOT_MEASURED, departures_frame, measured_effect


def differing_fields() -> set[str]:
    """Every model and training field in which the paper's profile differs from the book's."""
    out = set()
    for part in ("model", "train"):
        book, paper = asdict(getattr(BOOK, part)), asdict(getattr(PAPER, part))
        out |= {f"{part}.{k}" for k in book if book[k] != paper[k]}
    return out


def test_every_setting_the_paper_profile_takes_back_is_a_listed_departure():
    listed = {f for d in DEPARTURES for f in d.fields}
    assert differing_fields() - listed == set(), "a departure of the recipe is missing from the table"
    assert listed - differing_fields() == set(), "the table lists a field the paper profile does not change"


def test_each_measured_effect_comes_from_its_result_file():
    frame = departures_frame()
    assert list(frame.index) == [d.what for d in DEPARTURES]
    for d in DEPARTURES:
        effect = frame.loc[d.what, "measured effect"]
        if d.evidence is None:
            assert effect == NOT_MEASURED
        elif d.evidence[0] != "scaling":
            assert ".json)" in effect, effect              # names the file it read


def test_an_ablation_effect_follows_its_result_file(monkeypatch):
    cells = next(d for d in DEPARTURES if d.what == "LSTM cell")
    assert "no cell of Table 1 differs" in measured_effect(cells)
    monkeypatch.setattr(departures.results, "ablation_verdict", lambda frame: "beyond the spread: describe (worse)")
    assert "beyond the spread: describe (worse)" in measured_effect(cells)


def test_a_scaling_effect_without_its_result_file_is_not_measured(monkeypatch):
    scale = next(d for d in DEPARTURES if d.what == "the opposite view's scale")
    monkeypatch.setattr(departures.results, "names", lambda: [])
    assert measured_effect(scale) == NOT_MEASURED


@pytest.mark.parametrize("field", ["model.cell", "train.vision_scaling"])
def test_fields_name_real_settings(field):
    part, name = field.split(".")
    assert name in asdict(getattr(BOOK, part))
