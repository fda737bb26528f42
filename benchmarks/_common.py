"""What the scripts in this folder share: one-line errors, source trees, maps and queries.

A script here runs from the repository root (``python benchmarks/NAME.py ...``) with the
skyroute it measures importable (``PYTHONPATH=src``), or names the source trees it
compares (:func:`resolve_tree`).
"""

from __future__ import annotations

import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent


class Fail(Exception):  # noqa: N818 (the scripts raise it as `raise Fail(...)`)
    """Bad input: the script prints ``NAME: error: MESSAGE`` and exits 2."""


def parser(prog: str, description: str) -> argparse.ArgumentParser:
    """An argument parser that takes an argument starting with ``-`` and a digit or a
    point as a value: a query whose first coordinate is negative (``'-300,250;0,0'``),
    typed as is. argparse reads as a value only a plain negative number (``-5``) and
    refused such a query as an unknown option, unless ``--`` came before it. (Its
    pattern for negative numbers is an attribute without a public setter; no option of
    these scripts looks like a negative number.)"""
    p = argparse.ArgumentParser(prog=prog, description=description)
    p._negative_number_matcher = re.compile(r"^-\.?\d")
    return p


def ned_queries(texts: list[str], *, headings: bool = True) -> list[tuple]:
    """``(text, start, goal)`` of each ``'N,E[,HEADING];N,E[,HEADING]'`` in ``texts``:
    metres in the NED frame, headings (with ``headings``) degrees clockwise from north,
    returned in radians; a :class:`Fail` naming the query that is not one."""
    form = "N,E or N,E,HEADING" if headings else "N,E"
    out = []
    for q in texts:
        parts = q.split(";")
        if len(parts) != 2:
            raise Fail(f"query {q!r}: expected START;GOAL")
        poses = []
        for text in parts:
            try:
                v = [float(x) for x in text.split(",")]
            except ValueError:
                v = []
            if len(v) not in ((2, 3) if headings else (2,)) or \
                    not all(math.isfinite(x) for x in v):
                raise Fail(f"query {q!r}: {text!r} is not {form}")
            poses.append((v[0], v[1]) + ((math.radians(v[2]),) if len(v) == 3 else ()))
        out.append((q, *poses))
    return out


def check_counts(args, names: tuple[str, ...], low: int = 1, high: int = 100) -> None:
    """A :class:`Fail` naming the first of the options ``names`` (attributes of the
    parsed ``args``) whose value lies outside ``low`` to ``high``."""
    for name in names:
        if not low <= getattr(args, name) <= high:
            raise Fail(f"--{name} {getattr(args, name)}: expected {low} to {high}")


def run_main(main) -> None:
    """Run ``main()``; a :class:`Fail` or a skyroute input error is one line, exit 2."""
    name = Path(sys.argv[0]).name
    try:
        main()
    except Fail as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    except KeyboardInterrupt:
        raise SystemExit(130) from None
    except Exception as exc:  # skyroute's own input errors name the file and line
        if type(exc).__module__.startswith("skyroute") and "Error" in type(exc).__name__:
            print(f"{name}: error: {exc}", file=sys.stderr)
            raise SystemExit(2) from None
        raise


def skyroute_in(folder: Path) -> Path | None:
    """The folder to put on ``PYTHONPATH`` so that ``folder``'s skyroute is imported:
    ``folder`` itself when it holds ``skyroute/__init__.py``, its ``src`` when that does
    (a checkout's root), else None."""
    for cand in (folder, folder / "src"):
        if (cand / "skyroute" / "__init__.py").is_file():
            return cand.resolve()
    return None


def resolve_tree(spec: str, keep: list, repo: Path = REPO) -> Path:
    """The import folder of the source tree ``spec``: a folder (a checkout, its ``src``,
    or any folder holding ``skyroute/``), else a commit of ``repo`` (``git archive COMMIT
    src`` into a temporary folder, appended to ``keep`` so that it lives as long as the
    caller wants it)."""
    folder = Path(spec).expanduser()
    if folder.exists():
        found = skyroute_in(folder)
        if found is None:
            raise Fail(f"tree {spec!r}: the folder holds no skyroute package (neither "
                       f"{spec}/skyroute/__init__.py nor {spec}/src/skyroute/__init__.py)")
        return found
    git = ["git", "-C", str(repo)]
    ok = subprocess.run([*git, "rev-parse", "--verify", "--quiet", f"{spec}^{{commit}}"],
                        capture_output=True, text=True)
    if ok.returncode != 0:
        raise Fail(f"tree {spec!r}: neither a folder nor a commit of {repo}")
    tmp = tempfile.TemporaryDirectory(prefix=f"tree-{spec[:12]}-".replace("/", "_"))
    keep.append(tmp)
    archive = subprocess.run([*git, "archive", ok.stdout.strip(), "src"],
                             capture_output=True)
    if archive.returncode != 0:
        raise Fail(f"tree {spec!r}: git archive failed: "
                   + (archive.stderr.decode().strip().splitlines() or ["no message"])[-1])
    subprocess.run(["tar", "-x", "-C", tmp.name], input=archive.stdout, check=True)
    found = skyroute_in(Path(tmp.name))
    if found is None:
        raise Fail(f"tree {spec!r}: commit {ok.stdout.strip()[:12]} has no src/skyroute")
    return found


def env_for(tree: Path) -> dict:
    """The environment of a process that imports ``tree``'s skyroute (and nothing else's:
    ``PYTHONPATH`` is that folder alone)."""
    return {**os.environ, "PYTHONPATH": str(tree)}


def measure_in(tree: Path, argv: list[str], label: str) -> dict:
    """Run ``python ARGV`` in a process that imports ``tree``'s skyroute and read the
    JSON object on the last line it prints, whose ``skyroute`` names the package it
    imported: a :class:`Fail` naming the tree (``label``) when the process fails or
    imported another skyroute (an installed, non-editable one)."""
    import json

    proc = subprocess.run([sys.executable, *argv], capture_output=True, text=True,
                          env=env_for(tree))
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise Fail(f"tree {label} ({tree}): the measuring process failed: {last}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    if not Path(out["skyroute"]).resolve().is_relative_to(tree):
        raise Fail(f"tree {label}: the measuring process imported {out['skyroute']}, "
                   f"not the skyroute of {tree} (is skyroute installed non-editable?)")
    return out


def parse_random(spec: str) -> tuple[int, float]:
    """``512:0.2`` -> (512, 0.2)."""
    side, _, share = spec.partition(":")
    try:
        n, p = int(side), float(share)
    except ValueError:
        n, p = 0, -1.0
    if not (2 <= n <= 4096 and 0.0 <= p < 1.0):
        raise Fail(f"--random {spec!r}: expected SIDE:SHARE with 2 <= SIDE <= 4096 and "
                   "0 <= SHARE < 1, e.g. 512:0.2")
    return n, p


def random_blocked(side: int, share: float, seed: int) -> np.ndarray:
    """The blocked cells of ``skyroute.bench.random_maps.random_grid(side, share, seed)``
    (the same draws), without importing skyroute: a tree under test may predate it."""
    return np.random.default_rng(seed).random((side, side)) < share


def scen_of(map_path: Path) -> Path:
    """The scenario file of a MovingAI map, as ``skyroute bench grid`` pairs them:
    ``X.map.scen``, else the first ``X-*.scen``."""
    scen = map_path.with_name(map_path.name + ".scen")
    if scen.is_file():
        return scen
    alts = sorted(map_path.parent.glob(map_path.stem + "-*.scen"))
    if not alts:
        raise Fail(f"--map {map_path}: no scenario file beside it ({scen.name} or "
                   f"{map_path.stem}-*.scen)")
    return alts[0]


def case_of(*, random: str | None = None, map_path: str | None = None, queries: int,
            seed: int) -> dict:
    """One map and its queries, as ``skyroute bench grid`` makes them: a random map's
    far queries (``far_queries``, seed ``seed``), or ``queries`` lines of a MovingAI
    map's scenario sampled with seed ``seed``. Uses the skyroute this process imports;
    ``{"name", "blocked", "starts", "goals", "optimal"}``."""
    if random is not None:
        from skyroute.bench.random_maps import far_queries, random_grid

        side, share = parse_random(random)
        grid = random_grid(side, share, seed)
        scen = far_queries(grid, queries, seed)
        idx = np.arange(len(scen))
        name = grid.name
    else:
        from skyroute.bench.grid import check_scenario
        from skyroute.world.movingai import read_map, read_scen

        path = Path(map_path)
        if not path.is_file():
            raise Fail(f"--map {map_path}: no such file")
        grid, scen = read_map(path), read_scen(scen_of(path))
        check_scenario(grid, scen, path.name)
        n = min(queries, len(scen))
        idx = np.sort(np.random.default_rng(seed).choice(len(scen), size=n, replace=False))
        name = path.name
    return {"name": name, "blocked": np.asarray(grid.blocked, dtype=bool),
            "starts": scen.starts[idx].astype(np.int64),
            "goals": scen.goals[idx].astype(np.int64),
            "optimal": np.asarray(scen.optimal[idx], dtype=float)}


def load_average() -> str:
    """``load 1.2 / 0.9 / 0.7`` (1, 5, 15 minutes), or ``load unknown``."""
    try:
        return "load " + " / ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "load unknown"
