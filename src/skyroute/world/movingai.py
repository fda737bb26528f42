"""MovingAI benchmark files: ``.map`` grids and ``.scen`` scenario lists.

Format: https://movingai.com/benchmarks/formats.html (Sturtevant 2012). Terrain:
``.``, ``G`` and ``S`` are passable; ``@``, ``O``, ``T`` and ``W`` are blocked. Water
(``W``) is "traversable, but not passable from terrain", and no cost is given for it; a
ground robot starting on terrain can never enter it, so it is blocked here. LF and CRLF
line endings are accepted, with or without a final newline, and so are a UTF-8
byte-order mark (Windows editors write one) and blank lines (spaces only) at the end.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skyroute.errors import InputFormatError
from skyroute.files import cannot_read, strip_bom
from skyroute.world.grid import MAX_CELLS, Grid, check_file_cells

PASSABLE = ".GS"
BLOCKED = "@OTW"
# the largest file a map within MAX_CELLS can be: one byte a cell, a CRLF a row (rows of
# one cell: 3 bytes a cell), the header and some blank lines; a larger file is refused
# before it is read whole
MAX_BYTES = 3 * MAX_CELLS + (1 << 20)


def _lines(path: Path, raw: bytes | None = None, kind: str = "a map file") -> list[str]:
    if raw is None:
        try:
            if (size := path.stat().st_size) > MAX_BYTES:
                raise InputFormatError(path, f"{size:,} bytes, over the limit of "
                                       f"{MAX_BYTES:,} for {kind}")
            raw = path.read_bytes()
        except OSError as exc:
            raise cannot_read(path, exc) from None
    raw = strip_bom(raw)
    if not raw.strip():
        raise InputFormatError(path, "the file is empty", line=1)
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise InputFormatError(path, "not an ASCII text file", line=line) from None
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


def _header_int(path: Path, lines: list[str], index: int, key: str) -> int:
    parts = lines[index].split() if index < len(lines) else []
    if len(parts) != 2 or parts[0] != key:
        got = lines[index].strip() if index < len(lines) else "end of file"
        raise InputFormatError(path, f"expected '{key} N', got {got!r}", line=index + 1)
    try:
        value = int(parts[1])
    except ValueError:
        raise InputFormatError(path, f"{key} must be an integer, got {parts[1]!r}",
                               line=index + 1) from None
    if value < 1:
        raise InputFormatError(path, f"{key} must be >= 1, got {value}", line=index + 1)
    return value


def read_map(path: str | Path, *, text: str | bytes | None = None) -> Grid:
    """Read a MovingAI ``.map`` file into a :class:`Grid` with 1 m cells.

    ``text``: the file's content, already in hand (an upload); ``path`` then only names
    it in errors. Raises :class:`~skyroute.errors.InputFormatError` naming the line of a
    bad header, a row of the wrong width, an unknown character or a wrong number of rows.
    """
    path = Path(path)
    # (a lone surrogate, "\\ud800" in an upload's JSON, goes through as bytes that are
    # not ASCII: refused with its line as any other character, not a UnicodeEncodeError)
    lines = _lines(path, text.encode("utf-8", "surrogatepass") if isinstance(text, str)
                   else text)
    if not lines or lines[0].split() != ["type", "octile"]:
        got = lines[0].strip() if lines else "an empty file"
        raise InputFormatError(path, f"expected 'type octile', got {got!r}", line=1)
    height = _header_int(path, lines, 1, "height")
    width = _header_int(path, lines, 2, "width")
    # before the grid is allocated: 'width 1000000000000' was numpy's MemoryError
    check_file_cells(path, width, height, line=3, what="the header's map")
    if len(lines) < 4 or lines[3].strip() != "map":
        got = lines[3].strip() if len(lines) > 3 else "end of file"
        raise InputFormatError(path, f"expected 'map', got {got!r}", line=4)
    rows = lines[4:]
    while rows and not rows[-1].strip():
        rows.pop()
    if len(rows) != height:
        raise InputFormatError(
            path, f"header says height {height} but {len(rows)} map rows follow",
            line=4 + min(len(rows), height) + (1 if len(rows) > height else 0))
    table = np.full(256, 2, dtype=np.uint8)  # 2 = unknown character
    table[np.frombuffer(PASSABLE.encode(), np.uint8)] = 0
    table[np.frombuffer(BLOCKED.encode(), np.uint8)] = 1
    blocked = np.empty((height, width), dtype=bool)
    for r, row in enumerate(rows):
        if len(row) != width:
            raise InputFormatError(path, f"row {r} has {len(row)} characters, header says "
                                   f"width {width}", line=5 + r)
        codes = table[np.frombuffer(row.encode(), np.uint8)]
        if (codes == 2).any():
            col = int(np.argmax(codes == 2))
            raise InputFormatError(
                path, f"unknown terrain {row[col]!r} at column {col}; valid: "
                f"passable {PASSABLE!r}, blocked {BLOCKED!r}", line=5 + r)
        blocked[r] = codes == 1
    return Grid(blocked, 1.0, (0.0, 0.0), name=path.name)


@dataclass(frozen=True, eq=False)
class Scenario:
    """The queries of one ``.scen`` file, as parallel arrays (one row per line).

    ``width`` and ``height`` are the map's size, None for a version-0 file, which gives
    none. ``starts`` and ``goals`` are (N, 2) int arrays of (x, y) cells; ``optimal`` the
    octile lengths; ``tolerance`` the rounding of each printed length (half a unit of
    its last decimal), so a cost matches when ``|cost - optimal| <= tolerance``.
    """

    path: Path
    map_name: str
    width: int | None
    height: int | None
    buckets: np.ndarray
    starts: np.ndarray
    goals: np.ndarray
    optimal: np.ndarray
    tolerance: np.ndarray

    def __len__(self) -> int:
        return len(self.optimal)

    def matches(self, index: int, cost: float) -> bool:
        """True when ``cost`` equals line ``index``'s optimum to its printed precision
        plus 1e-6 relative: the legacy random512 file carries its generator's float
        error of up to about 5e-4 on top of its 5-decimal rounding."""
        opt = self.optimal[index]
        return abs(cost - opt) <= self.tolerance[index] + 1e-6 * opt


def query_line(path: str | Path, index: int) -> int | None:
    """The file line of a ``.scen`` file's ``index``-th query, counted as
    :func:`read_scen` counts it (blank lines skipped); for error messages. None when the
    file cannot be read."""
    try:
        lines = _lines(Path(path), kind="a scenario file")
    except InputFormatError:
        return None
    first = 1 if _version_line(lines) else 0
    numbers = [n for n, line in enumerate(lines[first:], start=first + 1) if line.strip()]
    return numbers[index] if index < len(numbers) else None


def _version_line(lines: list[str]) -> bool:
    """Whether line 1 is a version line (a file of version 0 may have none)."""
    return bool(lines) and lines[0].split()[:1] == ["version"]


def read_scen(path: str | Path) -> Scenario:
    """Read a MovingAI ``.scen`` file: ``version 1`` and 9 tab-separated columns, or the
    older version 0 (a ``version 0`` line or none, as HOG2's loader reads it) of 7
    columns, ``bucket map start_x start_y goal_x goal_y length``, which give no map size
    (``width`` and ``height`` are then None). Every line must name the same map."""
    path = Path(path)
    lines = _lines(path, kind="a scenario file")
    version = lines[0].split()[1:] if _version_line(lines) else ["0"]
    if len(version) != 1 or version[0] not in ("1", "1.0", "0", "0.0"):
        raise InputFormatError(path, f"expected 'version 1' (or 'version 0'), got "
                               f"{lines[0].strip()!r}", line=1)
    ncols = 9 if version[0].startswith("1") else 7
    first = 1 if _version_line(lines) else 0
    buckets, coords, optimal, tol = [], [], [], []
    map_name, size = None, None
    for n, line in enumerate(lines[first:], start=first + 1):
        if not line.strip():
            continue
        # a tab or space after the last column (an editor's, a script's) is no column
        cols = line.strip().split("\t")
        if len(cols) != ncols:
            spaced = " (its columns are separated by spaces)" \
                if len(line.split()) == ncols and " " in line.strip() else ""
            hint = "" if first or len(cols) != 9 else \
                " (a file of 9 columns starts with the line 'version 1')"
            raise InputFormatError(path, f"expected {ncols} tab-separated columns, got "
                                   f"{len(cols)}{spaced}{hint}", line=n)
        if ncols == 7:  # version 0: no map size
            cols = [cols[0], cols[1], "0", "0", *cols[2:]]
        try:
            nums = [int(c) for c in (cols[0], *cols[2:8])]
            length = float(cols[8])
        except ValueError:
            raise InputFormatError(path, "bucket, width, height, start_x, start_y, goal_x, "
                                   "goal_y must be integers and length a number", line=n) from None
        bucket, w, h, sx, sy, gx, gy = nums
        if map_name is None:
            map_name, size = cols[1].strip(), (w, h)
        elif cols[1].strip() != map_name:
            raise InputFormatError(path, f"map {cols[1].strip()!r} differs from the first "
                                   f"line's {map_name!r}", line=n)
        elif (w, h) != size:
            raise InputFormatError(path, f"map size {w}x{h} differs from the first line's "
                                   f"{size[0]}x{size[1]}", line=n)
        if ncols == 9 and not (0 <= sx < w and 0 <= gx < w and 0 <= sy < h and 0 <= gy < h):
            raise InputFormatError(path, f"start ({sx}, {sy}) or goal ({gx}, {gy}) lies "
                                   f"outside the {w}x{h} map", line=n)
        if not np.isfinite(length) or length < 0:
            raise InputFormatError(path, f"optimal length {cols[8]!r} must be >= 0", line=n)
        decimals = len(cols[8].strip().partition(".")[2])
        buckets.append(bucket)
        coords.append((sx, sy, gx, gy))
        optimal.append(length)
        tol.append(0.5 * 10.0 ** -decimals + 1e-9)
    if size is None:
        raise InputFormatError(path, "no scenario lines" + (" after the version line"
                                                            if first else ""), line=first + 1)
    width, height = size if ncols == 9 else (None, None)
    c = np.array(coords, dtype=np.int64).reshape(-1, 4)
    return Scenario(path, map_name or "", width, height, np.array(buckets, dtype=np.int64),
                    c[:, :2].copy(), c[:, 2:].copy(), np.array(optimal), np.array(tol))
