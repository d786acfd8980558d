"""``docs/regen.py run`` on the development seeds alone: every section whose commands read a held-out seed set (a
``--seed 100`` frame folder, seeds 100 and up) is left out, and the ``heldback`` and ``conf`` parts are refused.

    python docs/regen_dev.py run OUT PART ... [--jobs N] [--resume]   # from the tree to measure (PYTHONPATH=src)

Everything else (``compare``, ``list``: the commands kept) is the ``docs/regen.py`` beside this script. As with it,
``run`` measures the tree it is run from (its ``src``, ``docs/`` scripts and ``examples/``), so it measures a base
tree too: ``cd BASE && PYTHONPATH=src python /path/to/docs/regen_dev.py run OUT spheres``.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import sys
from pathlib import Path

#: A command reading a held-out set: seeds 100 and up (``--seed 100``, a ``seed-100`` frame folder).
HELD_OUT = re.compile(r"(--seed |seed-)(1\d\d|[2-9]\d\d|\d{4,})\b")
#: Parts made of held-out runs (the lead's).
REFUSED = ("heldback", "conf")


def load_regen() -> object:
    path = Path(__file__).resolve().with_name("regen.py")
    spec = importlib.util.spec_from_file_location("regen", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["regen"] = module
    spec.loader.exec_module(module)
    return module


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
        parser.add_argument("what", choices=("run", "compare", "readme", "list"), help="as docs/regen.py's")
        parser.add_argument("args", nargs=argparse.REMAINDER, help="as docs/regen.py's")
        parser.parse_args(argv)  # --help: the usage; nothing: the usage and an error
    regen = load_regen()
    every = regen.parts  # type: ignore[attr-defined]

    def development() -> dict:
        kept = {}
        for name, sections in every().items():
            kept[name] = [s for s in sections if not any(HELD_OUT.search(c.text()) for c in s.cmds)]
        return kept

    regen.parts = development  # type: ignore[attr-defined]
    if argv[:1] == ["run"] and any(a in REFUSED for a in argv[1:]):
        sys.exit(f"regen_dev: the parts {', '.join(REFUSED)} are held-out runs (the lead's)")
    if argv[:1] == ["run"] and not [a for a in argv[2:] if not a.startswith("-")]:
        sys.exit("regen_dev: name the parts to run")
    return int(regen.main(argv))  # type: ignore[attr-defined]


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
