"""docs/regen.py: the parts' commands, a tiny part run and resumed, and the known answers of compare and readme."""

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def regen():
    spec = importlib.util.spec_from_file_location("regen", ROOT / "docs" / "regen.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["regen"] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("regen", None)


ROWS = """# x

## a table

README table: README.md, after "**The table**"

    symfruit evaluate --whatever

| method | IoU | centre (mm) |
|---|---|---|
| raw | 0.500 | 12.3 |
| `evidence` | 0.900 | 1.20 (2 failed) |
seeds 0-11: 308 of 360 apples found (85.6%)
"""


def write_out(folder: Path, text: str, part: str = "x") -> Path:
    (folder / part).mkdir(parents=True)
    (folder / part / "rows.md").write_text(text)
    return folder


def check(regen, folder: Path, readme: str, text: str, out: str = "out") -> tuple[tuple[int, int, int], list[str]]:
    """``readme`` of an OUT holding ``text`` as part x's rows against a README.md of ``readme``."""
    (folder / "README.md").write_text(readme)
    said: list[str] = []
    return regen.check_readme(write_out(folder / out, text), folder, said.append), said


def test_every_part_is_defined_and_its_readme_anchor_is_in_readme(regen):
    parts = regen.parts()
    assert set(parts) == set(regen.PART_ORDER)
    texts = {name: (ROOT / name).read_text() for name in (regen.README, regen.ABLATION)}
    for name, sections in parts.items():
        assert sections, name
        for s in sections:
            assert s.cmds, (name, s.title)
            if s.anchor is not None:
                found = s.anchor[1] if isinstance(s.anchor[1], list) else [s.anchor[1]]
                for text in filter(None, found):
                    assert regen.readme_tables(texts[s.anchor[0]], text) is not None, (name, s.title, text)


def test_the_commands_keep_readmes_own(regen):
    texts = [c.text() for s in regen.parts()["heldback"] for c in s.cmds]
    assert texts[0] == "symfruit evaluate --protocol camera --sensor heldback --fruit all --n 30 --no-profile"
    assert texts[1].endswith("--no-profile --seed 1")
    trees = [c.text() for s in regen.parts()["trees"] for c in s.cmds]
    assert trees[0].startswith("symfruit evaluate --frames _scenes/scene-apple-tree-n-12-seed-100 --methods raw,")
    assert trees[0].endswith("--config _config/CW1.yaml")


def test_read_rows_labels_cells_and_a_printed_line(regen):
    rows = regen.read_rows(ROWS)
    assert rows[("a table", 1, "raw")] == (["method", "IoU", "centre (mm)"], ["0.500", "12.3"])
    assert rows[("a table", 1, "`evidence`")][1] == ["0.900", "1.20 (2 failed)"]
    assert rows[("a table", 0, "seeds 0-11")] == ([], ["308", "360", "85.6"])
    assert len(rows) == 3  # the command and the README line are not rows


def test_compare_lists_a_moved_cell_and_a_row_in_one_run_only(regen, tmp_path):
    old = write_out(tmp_path / "old", ROWS)
    new = write_out(tmp_path / "new", ROWS.replace("12.3", "12.4") + "| paper | 0.700 | 3.0 |\n")
    said = []
    assert regen.compare(old, new, 0.0, False, said.append) == 2
    assert "x | a table | raw | centre (mm): 12.3 -> 12.4" in said
    assert "x | a table | paper: only in NEW" in said
    assert said[-1] == "x: 6 of 7 cells the same"
    said.clear()
    assert regen.compare(old, new, 0.1, False, said.append) == 1  # 12.3 -> 12.4 within 0.1
    said.clear()
    assert regen.compare(old, old, 0.0, True, said.append) == 0
    assert "x | a table | raw | IoU: 0.500" in said and said[-1] == "x: 7 of 7 cells the same"


def test_compare_tolerance_never_hides_a_changed_text(regen):
    assert regen.same("0.900 / 1.20", "0.901 / 1.21", 0.02)
    assert not regen.same("0.900 / 1.20", "0.900 / 1.20 (1 failed)", 10)
    assert not regen.same("1,074 / 1,082", "1,075 / 1,082", 0.5)
    assert regen.same("1,074 / 1,082", "1,075 / 1,082", 1)


def test_readme_confirms_a_row_names_a_differing_cell_and_a_row_it_lacks(regen, tmp_path):
    root = tmp_path / "tree"
    root.mkdir()
    (root / "README.md").write_text(
        "intro\n\n**The table** (some command):\n\n| method | IoU | centre (mm) |\n|---|---|---|\n"
        "| raw | 0.500 | 12.3 |\n| evidence | 0.900 | 1.30 (2 failed) |\n\nafter\n| raw | 9 | 9 |\n"
    )
    out = write_out(tmp_path / "out", ROWS + "\n## another\n\nREADME table: README.md, after \"**The table**\"\n\n"
                    "| method | IoU |\n|---|---|\n| paper | 0.7 |\n")  # fmt: skip
    said = []
    assert regen.check_readme(out, root, said.append) == (1, 1, 1)
    assert "x | a table | raw: confirmed" in said
    assert "x | a table | `evidence`: differs: centre (mm): README 1.30 (2 failed), printed 1.20 (2 failed)" in said
    assert "x | another | paper: no README row of that label" in said
    assert said[-1] == "README rows confirmed 1, differing 1, printed rows without a README row 1"


def test_readme_reads_one_anchor_per_printed_table_and_leaves_out_counts_and_timings(regen, tmp_path):
    readme = (
        "**A**\n\n| m | x | ms per image |\n|---|---|---|\n| raw | 1.0 (+1.0) | 3.9 |\n\n"
        "**B**\n\n| m | y |\n|---|---|\n| raw | 2.0 |\n"
    )
    text = ('## t\n\nREADME table: README.md, after ["**A**", null, "**B**"]\n\n'
            "| m | x | ms per image |\n|---|---|---|\n| raw | 1.0 (+1.0) (n 12) | 4.2 |\n\n"
            "| m | z |\n|---|---|\n| raw | 7 |\n\n| m | y |\n|---|---|\n| raw | 2.5 |\n")  # fmt: skip
    counts, said = check(regen, tmp_path, readme, text)
    assert counts == (1, 1, 0)
    assert said[:2] == ["x | t | raw: confirmed", "x | t | raw: differs: y: README 2.0, printed 2.5"]


def test_readme_matches_by_value_where_the_columns_differ(regen, tmp_path):
    readme = "**T**\n\n| method | IoU mean | centre (mm) |\n|---|---|---|\n| raw | 0.224 | 20.3 |\n"
    text = ('## t\n\nREADME table: README.md, after "**T**"\n\n'
            "| method | IoU mean | IoU median | centre dev mean (mm) |\n|---|---|---|---|\n"
            "| raw | 0.224 | 0.230 | 20.4 |\n")  # fmt: skip
    counts, said = check(regen, tmp_path, readme, text)
    assert counts == (0, 1, 0)
    assert said[0] == "x | t | raw: differs: centre (mm): README 20.3, printed (not printed)"


def test_readme_reads_a_row_by_its_readme_label_and_a_share_written_without_a_space(regen, tmp_path):
    readme = "**P**\n\n| data | matched |\n|---|---|\n| photos, half 0 (dev) | 551 (99.5 %) |\n"
    text = ('## p\n\nREADME table: README.md, after "**P**"\n\nREADME labels: {"half 0": "photos, half 0 (dev)"}\n\n'
            "| data | matched |\n|---|---|\n| half 0 (503 images) | 551 (99.5%) |\n")  # fmt: skip
    assert check(regen, tmp_path, readme, text)[0] == (1, 0, 0)


def test_readme_names_the_tables_it_cannot_check(regen, tmp_path):
    out = write_out(tmp_path / "out", "## prose only\n\n    python docs/tree_masks.py\n\nseeds 0-11: 308 of 360\n")
    said = []
    assert regen.check_readme(out, tmp_path, said.append) == (0, 0, 0)
    assert said[0] == "x | prose only: no README table (its figures are in README's text: compare by hand)"


def test_a_tiny_part_runs_writes_its_rows_and_resumes_without_running_again(regen, tmp_path, monkeypatch):
    counter = tmp_path / "count"
    code = (f"import pathlib; p = pathlib.Path({str(counter)!r}); p.write_text(p.read_text() + 'x' if p.exists() "
            "else 'x'); print('| a | 1 | 2 |')")  # fmt: skip
    section = regen.Section("tiny", [regen.Cmd(("python", "-c", code))], regen.printed, ("README.md", "**T**"))
    ctx = regen.Ctx(tmp_path / "out", tmp_path, resume=False)
    regen.run_part("tiny", [section], ctx, 1)
    rows = (tmp_path / "out" / "tiny" / "rows.md").read_text()
    assert "## tiny" in rows and "| a | 1 | 2 |" in rows and counter.read_text() == "x"
    status = (tmp_path / "out" / "tiny" / "status.json").read_text()
    assert '"rc": 0' in status
    regen.run_part("tiny", [section], regen.Ctx(tmp_path / "out", tmp_path, resume=True), 1)
    assert counter.read_text() == "x"  # finished: kept
    regen.run_part("tiny", [section], regen.Ctx(tmp_path / "out", tmp_path, resume=False), 1)
    assert counter.read_text() == "xx"  # afresh without --resume


def test_resume_runs_again_a_command_that_failed(regen, tmp_path):
    counter = tmp_path / "count"
    code = f"import pathlib, sys; p = pathlib.Path({str(counter)!r}); p.write_text('x'); sys.exit(3)"
    section = regen.Section("fails", [regen.Cmd(("python", "-c", code))], regen.printed)
    regen.run_part("p", [section], regen.Ctx(tmp_path / "out", tmp_path, resume=False), 1)
    assert "(failed, exit 3: " in (tmp_path / "out" / "p" / "rows.md").read_text()
    counter.unlink()
    regen.run_part("p", [section], regen.Ctx(tmp_path / "out", tmp_path, resume=True), 1)
    assert counter.exists()


def test_a_failed_rows_printer_is_named_not_fatal(regen, tmp_path):
    def broken(results):
        raise KeyError("scores")

    section = regen.Section("broken", [regen.Cmd(("python", "-c", "print(1)"))], broken)
    regen.run_part("p", [section], regen.Ctx(tmp_path / "out", tmp_path, resume=False), 1)
    assert "(rows failed: KeyError: 'scores')" in (tmp_path / "out" / "p" / "rows.md").read_text()


def test_scan_labels_and_leaf_cells(regen, monkeypatch):
    assert regen.scan_label("scan/016_pear") == "real pear"
    assert regen.scan_label("scan/berry") == "real berry"
    fix = regen.relabel_scans("hanging")
    assert fix(["| scan/011_banana | 19 | 0.9 |"]) == ["| real banana, hanging | 19 | 0.9 |"]
    printed = ["| 0% | 70 | 0.753 / 4.60 / 15 / 2 / 0 |", "| 25% | 70 | 0.671 / 7.04 / 70 / 10 / 3 |"]
    monkeypatch.setattr(regen, "rows_script", lambda *args: printed)
    result = regen.Result(regen.Cmd(("x",)), Path("."), "", Path("."), 0, 0.0)
    assert regen.leaf_cells(["Azure Kinect"])([result])[-2:] == [
        "| Azure Kinect | 0.753 / 4.6 (2) | 0.671 / 7.0 (10) |",
        "",
    ]


def test_readme_leaves_out_the_columns_of_earlier_stops(regen, tmp_path):
    readme = "**L**\n\n| s | 0 % | 25 % at stop 39 |\n|---|---|---|\n| D435 | 0.768 | 0.524 |\n"
    text = '## l\n\nREADME table: README.md, after "**L**"\n\n| D435 | 0.768 |\n'
    assert check(regen, tmp_path, readme, text)[0] == (1, 0, 0)
    counts, said = check(regen, tmp_path, readme, text.replace("0.768", "0.770"), out="out2")
    assert counts == (0, 1, 0)
    assert said[0] == "x | l | D435: differs: 0 %: README 0.768, printed (not printed)"


def test_readme_write_rewrites_the_differing_cells_only(regen, tmp_path):
    """``regen.py readme OUT --write``: a printed row rewrites README's row of its label in the table after its
    anchor, keeping the cells README agrees with and the timing column, a count ``(n N)`` left out where README's
    cell has none; a printed row with other columns is left for the hand; the other tables and rows are untouched."""
    readme = (
        "# R\n\nOther table:\n\n| a | IoU |\n|---|---|\n| x | 0.1 |\n\n"
        "Anchor here:\n\n| a | IoU | centre (mm) | ms |\n|---|---|---|---|\n"
        "| x | 0.1 | 2.0 | 5 |\n| y | 0.3 | 1.0 | 6 |\n"
        "\nWide after:\n\n| a | IoU | centre (mm) |\n|---|---|---|\n| z | 0.5 | 9.9 |\n"
    )
    (tmp_path / "README.md").write_text(readme)
    rows = (
        '## Sec\n\nREADME table: README.md, after "Anchor here"\n\n'
        "| a | IoU | centre (mm) | ms |\n|---|---|---|---|\n"
        "| x | 0.2 | 2.5 (n 4) | 7 |\n| y | 0.3 | 1.0 | 6 |\n\n"
        '## Wide\n\nREADME table: README.md, after "Wide after"\n\n| a | IoU |\n|---|---|\n| z | 0.6 |\n'
    )
    (tmp_path / "out" / "p").mkdir(parents=True)
    (tmp_path / "out" / "p" / "rows.md").write_text(rows)
    said: list[str] = []
    confirmed, differ, unmatched = regen.check_readme(tmp_path / "out", tmp_path, said.append, write=True)
    assert (confirmed, differ, unmatched) == (1, 2, 0)
    text = (tmp_path / "README.md").read_text()
    assert "| x | 0.2 | 2.5 | 5 |" in text  # IoU and centre rewritten, (n 4) left out as README had it, timing kept
    assert "| x | 0.1 |\n" in text and "| y | 0.3 | 1.0 | 6 |" in text and "| z | 0.5 | 9.9 |" in text
    assert any("p | Wide | z: BY HAND" in x for x in said)
    assert not list(tmp_path.glob("*.tmp"))
    said.clear()
    assert regen.check_readme(tmp_path / "out", tmp_path, said.append) == (2, 1, 0)  # and nothing written now


def test_readme_write_reads_a_headerless_printed_row_of_readmes_cell_count_in_readmes_columns(regen, tmp_path):
    """Rows printed without a header (``docs/readme_rows.py``'s) whose cells are as many as README's row's are
    README's columns: checked cell by cell and rewritten; one with fewer cells is still matched by value only."""
    readme = "**C**\n\n| sensor | n | `raw` | `evidence` |\n|---|---|---|---|\n| D405 | 70 | 0.558 | 0.824 |\n"
    (tmp_path / "README.md").write_text(readme)
    (tmp_path / "out" / "p").mkdir(parents=True)
    rows = '## c\n\nREADME table: README.md, after "**C**"\n\n| D405 | 70 | 0.558 | 0.812 |\n'
    (tmp_path / "out" / "p" / "rows.md").write_text(rows)
    said: list[str] = []
    assert regen.check_readme(tmp_path / "out", tmp_path, said.append, write=True) == (0, 1, 0)
    assert said[0] == "p | c | D405: differs: `evidence`: README 0.824, printed 0.812"
    assert "| D405 | 70 | 0.558 | 0.812 |" in (tmp_path / "README.md").read_text()
    said.clear()
    assert regen.check_readme(tmp_path / "out", tmp_path, said.append) == (1, 0, 0)
