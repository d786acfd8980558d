"""The progress bar: a line every 10 % into logs, redrawn in place on a terminal, silent when off."""

import io
import re

from symfruit.progress import Progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_logs_get_a_line_per_tenth():
    stream = io.StringIO()
    with Progress(20, "detect", stream=stream) as bar:
        for _ in range(20):
            bar.update()
    lines = stream.getvalue().splitlines()
    counts = [1, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20]  # the first update, then each new tenth
    assert [re.sub(r" \(\d+\.\d s\)$", "", line) for line in lines] == [f"detect: {n}/20" for n in counts]
    assert all(re.fullmatch(r"detect: \d+/20 \(\d+\.\d s\)", line) for line in lines)
    assert len(lines) == 11 and lines[-1].startswith("detect: 20/20")


def test_batched_updates_count_every_item():
    stream = io.StringIO()
    with Progress(100, "evaluate", stream=stream) as bar:
        bar.update(50)
        bar.update(50)
    assert bar.done == 100 and [line.split(" (")[0] for line in stream.getvalue().splitlines()] == [
        "evaluate: 50/100",
        "evaluate: 100/100",
    ]


def test_a_terminal_is_redrawn_in_place_and_left_on_a_new_line():
    stream = Terminal()
    with Progress(4, "x", stream=stream) as bar:
        for _ in range(4):
            bar.update()
    text = stream.getvalue()
    assert text.count("\r") == 4 and text.endswith("\n") and "\n" not in text[:-1]
    assert "[" + "#" * 30 + "] 4/4" in text and "[" + "#" * 7 + " " * 23 + "] 1/4" in text


def test_disabled_or_empty_bars_print_nothing():
    for total, enabled in ((5, False), (0, True), (-3, True)):
        stream = Terminal()
        with Progress(total, "x", stream=stream, enabled=enabled) as bar:
            bar.update()
        assert stream.getvalue() == "" and bar.done == 1
