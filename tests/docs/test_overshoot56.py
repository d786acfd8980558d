"""docs/overshoot56.py (stop 56, docs/overshoot56.md): the lateral sides against the 2D thin-lens estimate, both
less the unperturbed mask's diameter, read from ``docs/realpert55.py run``'s boxes."""

import json
from pathlib import Path

import pytest

from ..conftest import docs_script


@pytest.fixture(scope="module")
def ov():
    return docs_script("overshoot56")


def _write(out: Path, name: str, rows: list[tuple[int, tuple[float, float, float], float]]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    data = [{"frame": "f", "sphere": k, "method": "evidence", "size": list(size), "diameter": d, "error": ""}
            for k, size, d in rows]  # fmt: skip
    (out / f"{name}.json").write_text(json.dumps({"failed": {}, "rows": data}))


def test_lateral_sides_and_thin_lens_are_judged_against_the_unperturbed_diameter(ov, tmp_path):
    _write(tmp_path / "a", "none", [(1, (100.0, 101.0, 99.0), 100.0), (2, (60.0, 59.0, 61.0), 60.0)])
    # grown masks: thin-lens +8 and +4 mm; the boxes' larger lateral sides +6 (better) and +5 (worse)
    _write(tmp_path / "a", "dilate5", [(1, (106.0, 104.0, 105.0), 108.0), (2, (64.0, 65.0, 66.0), 64.0)])
    _write(tmp_path / "b", "dilate5", [(1, (102.0, 101.0, 105.0), 108.0), (2, (61.0, 60.0, 66.0), 64.0)])
    table = ov.lateral(tmp_path / "a", tmp_path / "b").splitlines()
    assert table[2] == "| none | 0.0 (+0.0) | 0.5 (+0.5) | 1 / 2 |"  # no OUT2 run of it: no cell
    assert table[3] == "| dilate5 | 6.0 (+6.0) | 5.5 (+5.5) | 1 / 2 | 1.5 (+1.5), 0 worse |"
