"""What a fleet run leaves on disk (issue 11, section 5): :func:`write_run` writes, in
one folder, each file whole or not at all (:func:`skyroute.files.write_atomic`):

``report.json``
    the report's numbers (:func:`skyroute.fleet.report.report`), indent 2, in its order.
``events.jsonl``
    one compact JSON object a line per event of the run, in the run's order: the same
    scenario, seed and settings give the same bytes.
``tracks.csv``
    ``t,drone,north,east,alt,phase``: every drone in flight (gate to gate; a parked
    drone has no rows) at every multiple of the track step within the run, sorted by
    time then drone; metres north, east and up from the scenario's home. Phases are
    :data:`TRACK_PHASES` (``taxi`` out and in; ``landing`` only at the very instant of
    touchdown); ground phases have altitude 0.
``packages.csv``
    one row per package spawned in the run (:data:`PACKAGE_HEADER`): its times (empty
    when it had not happened by the end of the run), the drone assigned to it, and its
    state at the end.
``fleet.geojson``
    airports, gates, runways and one airborne track per flight, in lon/lat (WGS84).
``map.png``, ``timeline.png`` (``plot=True``)
    the map of tracks by drone; packages waiting, carried and delivered over time, with
    the loiter circles and the warm-up window.

Everything after the horizon is left out, as the event log leaves it out: a flight
released before the end but still flying at it has rows up to the horizon only.

>>> from skyroute.fleet.scenario import preset
>>> from skyroute.fleet.simulate import run
>>> sim = run(preset("seed-3x3"), hours=0.25, seed=1)
>>> tr = tracks(sim, step=1.0)
>>> [str(p) for p in TRACK_PHASES if p in tr["phase"]]
['taxi', 'takeoff', 'climb', 'cruise', 'loiter', 'approach', 'rollout']
>>> bool((tr["alt"][tr["phase"] == "taxi"] == 0).all())
True
>>> tracks_csv(sim, step=1.0).splitlines()[:2]
[b't,drone,north,east,alt,phase', b'40,1,-930.920,-974.302,0.000,taxi']
>>> events_jsonl(sim).splitlines()[0]
'{"t":24.803,"kind":"spawn","package":0,"airport":"B","gate":0}'
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

from skyroute.errors import OptionError, SkyrouteError
from skyroute.files import check_writable, remove_atomic, write_atomic, written_together
from skyroute.fleet.flightplan import FlightPlan, gate_position, ground_position
from skyroute.fleet.scenario import runway_ends
from skyroute.fleet.simulate import TIME_DECIMALS, WARMUP_SHARE, Simulation
from skyroute.fleet.trajectory import position
from skyroute.geo import Home, ned_to_lonlat
from skyroute.io.geojson import dumps
from skyroute.io.json_text import to_json

TRACK_PHASES = ("taxi", "takeoff", "climb", "cruise", "loiter", "approach", "landing",
                "rollout")
TRACK_HEADER = ("t", "drone", "north", "east", "alt", "phase")
PACKAGE_HEADER = ("id", "spawn_s", "from_airport", "from_gate", "to_airport", "to_gate",
                  "assigned_s", "pickup_s", "delivered_s", "drone", "state")
PACKAGE_STATES = ("waiting", "assigned", "carried", "delivered")
# a flight plan's phases as track phases; the airborne ones take positions from pieces
_CODE = {"taxi_out": 0, "takeoff": 1, "climb": 2, "cruise": 3, "loiter": 4, "approach": 5,
         "landing": 6, "rollout": 7, "taxi_in": 0}
_AIRBORNE = np.array([False, False, True, True, True, True, False, False])
_DECIMALS = 3  # millimetres in tracks.csv
_CHUNK = 1 << 18  # rows formatted at a time (bounds the memory of tracks_csv)
RUN_FILES = ("report.json", "events.jsonl", "tracks.csv", "packages.csv", "fleet.geojson")
PLOT_FILES = ("map.png", "timeline.png")
_BY_AIRPORT = 12  # the timeline names airports up to this many


def write_run(sim: Simulation, rep: dict, out: str | Path, *, track_step: float = 1.0,
              plot: bool = False) -> list[Path]:
    """Write the files of the module docstring for run ``sim`` with report ``rep`` into
    folder ``out`` (created when missing); tracks every ``track_step`` seconds; the two
    PNGs only with ``plot`` (without it, those of an earlier run in ``out`` are removed
    with the others' renames). Returns the paths written, in that order."""
    out = Path(out)
    _check_step("track_step", track_step)
    try:
        report_text = to_json(rep, indent=2) + "\n"  # a NaN or an infinity: null
    except (TypeError, ValueError) as exc:
        raise OptionError(f"rep cannot be written as JSON: {exc}", param="rep") from None
    paths = check_run_outputs(out, plot=plot)  # none written if one cannot be
    with written_together():  # a Ctrl-C halfway leaves none of them, nor a mix of runs
        write_atomic(paths[0], report_text)
        write_atomic(paths[1], events_jsonl(sim))
        write_atomic(paths[2], _tracks_csv(sim, track_step))
        write_atomic(paths[3], packages_csv(sim))
        write_atomic(paths[4], dumps(fleet_geojson(sim)))
        if plot:
            plot_map(sim, paths[5])
            plot_timeline(sim, paths[6])
        else:  # an earlier run's maps would be read as this one's
            for stale in run_outputs(out, plot=True)[len(RUN_FILES):]:
                if stale.is_file() or stale.is_symlink():
                    remove_atomic(stale)
    return paths


def run_outputs(out: str | Path, *, plot: bool = False) -> list[Path]:
    """The files :func:`write_run` writes into ``out``, in its order."""
    names = RUN_FILES + (PLOT_FILES if plot else ())
    return [Path(out) / n for n in names]


def check_run_outputs(out: str | Path, *, plot: bool = False) -> list[Path]:
    """Fail now, before a run is simulated, if a file :func:`write_run` would write into
    ``out`` cannot be written (:func:`skyroute.files.check_writable`: a folder in its
    place, a file where the folder must be, no permission); the paths otherwise."""
    paths = run_outputs(out, plot=plot)
    for p in paths:
        check_writable(p)
    return paths


def events_jsonl(sim: Simulation) -> str:
    """``sim.events`` as JSON lines: compact, keys in each event's order."""
    return "".join(to_json(e, separators=(",", ":")) + "\n" for e in sim.events)


# -- tracks -------------------------------------------------------------------------
def tracks(sim: Simulation, step: float = 1.0) -> dict[str, np.ndarray]:
    """The rows of ``tracks.csv`` as columns: ``t`` (s), ``drone``, ``north``, ``east``,
    ``alt`` (m) and ``phase`` (one of :data:`TRACK_PHASES`), sorted by time then drone."""
    k, drone, pos, code = _track_arrays(sim, step)
    return {"t": k * float(step), "drone": drone, "north": pos[:, 0], "east": pos[:, 1],
            "alt": pos[:, 2], "phase": np.array(TRACK_PHASES)[code]}


def tracks_csv(sim: Simulation, step: float = 1.0) -> bytes:
    """``tracks.csv``: the header and the rows of :func:`tracks`, positions to the
    millimetre, times with as few decimals as ``step`` needs (none for whole seconds)."""
    return bytes(_tracks_csv(sim, step))


def _tracks_csv(sim: Simulation, step: float) -> bytearray:
    """:func:`tracks_csv` without the final copy (a big run's file is big)."""
    k, drone, pos, code = _track_arrays(sim, step)
    step = float(step)
    t_dec = _step_decimals(step)
    buf = bytearray((",".join(TRACK_HEADER) + "\n").encode())
    names = _text_table(TRACK_PHASES)
    scale = 10 ** _DECIMALS
    for a in range(0, len(k), _CHUNK):
        s = slice(a, a + _CHUNK)
        p = np.rint(pos[s] * scale).astype(np.int64)
        t = np.rint(k[s] * step * 10 ** t_dec).astype(np.int64)
        fields = [_fixed(t, t_dec), _fixed(drone[s], 0),
                  *(_fixed(p[:, j], _DECIMALS) for j in range(3)),
                  (names[0][code[s]], names[1][code[s]])]
        buf += _lines(fields)
    return buf


def _track_arrays(sim: Simulation, step: float):
    """(k, drone, positions (n, 3), phase codes): every flight on the grid ``k * step``
    within the flight and the run, sorted by k then drone."""
    step = _check_step("step", step)
    ks, drones, poss, codes = [], [], [], []
    for f in sim.flights:
        k, pos, code = _flight_track(f.plan, step, sim.horizon)
        ks.append(k)
        drones.append(np.full(len(k), f.plan.drone, dtype=np.int64))
        poss.append(pos)
        codes.append(code)
    if not ks:
        return (np.empty(0, np.int64), np.empty(0, np.int64), np.empty((0, 3)),
                np.empty(0, np.int8))
    k, drone = np.concatenate(ks), np.concatenate(drones)
    pos, code = np.concatenate(poss), np.concatenate(codes)
    order = np.lexsort((drone, k))
    k, drone, pos, code = k[order], drone[order], pos[order], code[order]
    # a drone whose next flight leaves at the very instant it reached the gate (no
    # hand-over time): one row, the arrival's
    keep = np.ones(len(k), dtype=bool)
    keep[1:] = (k[1:] != k[:-1]) | (drone[1:] != drone[:-1])
    return k[keep], drone[keep], pos[keep], code[keep]


def _flight_track(plan: FlightPlan, step: float, horizon: float):
    """(k, positions, phase codes) of one flight at the times ``k * step`` in
    ``[depart, at_gate]`` and ``[0, horizon]``."""
    lo, hi = max(plan.depart, 0.0), min(plan.at_gate, horizon)
    k = np.arange(math.ceil(lo / step), math.floor(hi / step) + 1, dtype=np.int64)
    t = k * step
    inside = (t >= lo) & (t <= hi)  # float rounding at the ends
    k, t = k[inside], t[inside]
    code = np.full(len(t), -1, dtype=np.int8)
    last = len(plan.phases) - 1
    for i, ph in enumerate(plan.phases):
        # phases are [start, end); the first claims a shared end, so the landing instant
        # (an empty phase) is itself and the last phase holds the arrival at the gate
        if ph.end > ph.start:
            at = (t >= ph.start) & ((t < ph.end) | ((i == last) & (t == ph.end)))
        else:
            at = t == ph.start
        code[at & (code < 0)] = _CODE[ph.name]
    if (code < 0).any():
        raise SkyrouteError(f"drone {plan.drone}'s flight at {plan.depart:.3f} s has no "
                            f"phase at t={t[code < 0][0]} s")
    pos = np.zeros((len(t), 3))
    air = _AIRBORNE[code]
    if (~air).any():
        pos[~air, :2] = ground_position(plan, t[~air])
    if air.any():
        pos[air] = position(plan.pieces, t[air], drone=plan.drone)
    if np.isnan(pos).any():
        raise SkyrouteError(f"drone {plan.drone}'s flight at {plan.depart:.3f} s has no "
                            f"position at t={t[np.isnan(pos).any(axis=1)][0]} s")
    return k, pos, code


def _check_step(name: str, step) -> float:
    try:
        s = float(step)
    except (TypeError, ValueError):
        s = math.nan
    if not (math.isfinite(s) and s > 0):
        raise OptionError(f"{name}={step!r} must be a number of seconds > 0", param=name)
    return s


def _step_decimals(step: float) -> int:
    """The fewest decimals (up to 6) that write every multiple of ``step`` exactly."""
    for d in range(7):
        x = float(step) * 10 ** d
        if abs(x - round(x)) <= 1e-9 * max(1.0, x):
            return d
    return 6


# -- fast fixed-point CSV -----------------------------------------------------------
def _fixed(m: np.ndarray, decimals: int) -> tuple[np.ndarray, np.ndarray]:
    """The integers ``m`` written as ``m / 10**decimals`` with ``decimals`` places, right
    aligned: ASCII codes ``(n, width)`` and which of them belong to the number (the
    rest is padding on the left). Vectorised: one pass per character column."""
    m = np.asarray(m, dtype=np.int64)
    neg = m < 0
    rest = np.abs(m)
    digits = np.full(len(m), decimals + 1)  # at least "0.xxx"
    p = 10 ** (decimals + 1)
    while (more := rest >= p).any():
        digits += more
        p *= 10
    dot = 1 if decimals else 0
    width = int(digits.max(initial=decimals + 1)) + dot + 1  # and a sign
    body = digits + dot
    chars = np.empty((len(m), width), dtype=np.uint8)
    keep = np.empty((len(m), width), dtype=bool)
    for j in range(width):  # the j-th character from the right
        col = width - 1 - j
        if dot and j == decimals:
            chars[:, col] = ord(".")
            keep[:, col] = True
            continue
        chars[:, col] = ord("0") + rest % 10
        rest //= 10
        sign = neg & (body == j)
        chars[sign, col] = ord("-")
        keep[:, col] = (j < body) | sign
    return chars, keep


def _text_table(names) -> tuple[np.ndarray, np.ndarray]:
    """ASCII codes ``(len(names), width)`` of short words and which are letters, to be
    indexed by a code column."""
    b = np.array([n.encode() for n in names])
    width = b.dtype.itemsize
    chars = b.view(np.uint8).reshape(len(names), width)
    return chars, np.arange(width) < np.array([len(n) for n in names])[:, None]


def _lines(fields) -> bytes:
    """CSV lines from ``(chars, keep)`` fields of equal row counts."""
    n = len(fields[0][0])
    comma = (np.full((n, 1), ord(","), np.uint8), np.ones((n, 1), bool))
    newline = (np.full((n, 1), ord("\n"), np.uint8), np.ones((n, 1), bool))
    parts = [x for f in fields for x in (f, comma)]
    parts[-1] = newline  # the comma after the last field
    chars = np.concatenate([c for c, _ in parts], axis=1)
    keep = np.concatenate([k for _, k in parts], axis=1)
    return chars[keep].tobytes()


# -- packages -----------------------------------------------------------------------
def package_states(sim: Simulation) -> np.ndarray:
    """The state (one of :data:`PACKAGE_STATES`) of every package of ``sim.stream`` at
    the horizon (``waiting`` also for packages never spawned)."""
    H = sim.horizon
    state = np.zeros(len(sim.stream), dtype=np.int64)
    for code, when in enumerate((sim.assigned, sim.pickup, sim.delivered), start=1):
        state[when <= H] = code
    return np.array(PACKAGE_STATES)[state]


def packages_csv(sim: Simulation) -> str:
    """``packages.csv``: one row per package spawned before the horizon, times in
    seconds (empty when not reached by the horizon); ``drone`` is the drone assigned to
    the package (which fetches and carries it), empty while it waits."""
    st, H = sim.stream, sim.horizon
    ids = [a.id for a in sim.scenario.airports]
    drone = np.full(len(st), -1, dtype=np.int64)
    for e in sim.events:
        if e["kind"] == "assign":
            drone[e["package"]] = e["drone"]
    state = package_states(sim)

    def when(x: float) -> str:
        return f"{x:.{TIME_DECIMALS}f}" if x <= H else ""  # NaN too

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(PACKAGE_HEADER)
    for p in np.flatnonzero(st.t < H):  # the run spawns these (one per package)
        w.writerow([int(p), when(st.t[p]), ids[st.origin[p]], int(st.origin_gate[p]),
                    ids[st.destination[p]], int(st.destination_gate[p]),
                    when(sim.assigned[p]), when(sim.pickup[p]), when(sim.delivered[p]),
                    "" if drone[p] < 0 else int(drone[p]), state[p]])
    return buf.getvalue()


# -- GeoJSON ------------------------------------------------------------------------
def airborne_samples(plan: FlightPlan, step: float, horizon: float):
    """(times, positions (n, 3)) of a flight's airborne part within ``[0, horizon]``:
    every ``step`` seconds and at every piece's ends (so straights are exact); empty
    when it was not airborne in the run."""
    p = plan.pieces
    lo, hi = max(float(p.t0.min()), 0.0), min(float(p.t1.max()), horizon)
    if not hi > lo:
        return np.empty(0), np.empty((0, 3))
    t = np.concatenate([np.arange(math.ceil(lo / step), math.floor(hi / step) + 1) * step,
                        p.t0, p.t1, [lo, hi]])
    t = np.unique(t[(t >= lo) & (t <= hi)])
    return t, position(p, t, drone=plan.drone)


def fleet_geojson(sim: Simulation, step: float = 2.0) -> dict:
    """A FeatureCollection in lon/lat (WGS84, from the scenario's home): airports
    (``kind`` ``airport``), gates (``gate``), runways (``landing``, ``takeoff``: threshold
    to far end), no-fly zones (``no_fly_zone``: a Polygon with the zone's ``name``) and
    one LineString per flight airborne in the run (``kind``
    ``reposition`` or ``delivery``; lift-off to touchdown or the horizon, sampled every
    ``step`` seconds and at every piece's ends). Track points carry a third coordinate,
    the flight's altitude in metres above the airports."""
    step = _check_step("step", step)
    s = sim.scenario
    home = Home(lon=s.home_lon, lat=s.home_lat)
    ground = _ground(s)
    flights = []
    for f in sim.flights:
        t, pos = airborne_samples(f.plan, step, sim.horizon)
        if len(t) >= 2:
            flights.append((f, pos))
    ne = np.concatenate([g[1] for g in ground] + [pos[:, :2] for _, pos in flights])
    lonlat = np.round(ned_to_lonlat(ne[:, 0], ne[:, 1], -_alts(ground, flights), home)
                      [:, :2], 7)
    features = _ground_features(ground, lonlat)
    i = sum(len(pts) for _, pts in ground)
    for f, pos in flights:
        ll = np.column_stack([lonlat[i:i + len(pos)], np.round(pos[:, 2], 2)]).tolist()
        i += len(pos)
        plan = f.plan
        features.append({"type": "Feature",
                         "geometry": {"type": "LineString", "coordinates": ll},
                         "properties": {"kind": f.kind, "drone": plan.drone,
                                        "package": f.package, "loiters": plan.loiters,
                                        "origin": plan.origin, "origin_gate": plan.origin_gate,
                                        "destination": plan.destination,
                                        "destination_gate": plan.destination_gate,
                                        "altitude_m": plan.altitude,
                                        "depart_s": round(plan.depart, 3),
                                        "at_gate_s": round(plan.at_gate, 3)}})
    return {"type": "FeatureCollection", "features": features}


def fleet_geojson_from_tracks(scenario, tracks_csv_text: str | bytes) -> dict:
    """What a store keeps of a run (its scenario and ``tracks.csv``) as a FeatureCollection
    in lon/lat: the airports, gates, runways and no-fly zones of :func:`fleet_geojson`,
    and one
    LineString (``kind`` ``track``; lon, lat, altitude) per stretch a drone is airborne in
    the tracks, with its ``drone``, ``t0_s`` and ``t1_s``. Coarser than the run's own
    file: the tracks' step, without package or flight plan."""
    s = scenario
    home = Home(lon=s.home_lon, lat=s.home_lat)
    ground = _ground(s)
    text = tracks_csv_text.decode() if isinstance(tracks_csv_text, bytes) else tracks_csv_text
    rows = list(csv.reader(io.StringIO(text)))
    if rows and tuple(rows[0]) != TRACK_HEADER:
        raise SkyrouteError(f"tracks.csv: header {rows[0]!r}; expected {TRACK_HEADER!r}")
    body = rows[1:]
    t = np.array([float(r[0]) for r in body])
    drone = np.array([int(r[1]) for r in body], dtype=np.int64)
    pos = np.array([[float(v) for v in r[2:5]] for r in body]).reshape(-1, 3)
    up = np.array([r[5] in ("climb", "cruise", "loiter", "approach") for r in body],
                  dtype=bool)
    order = np.lexsort((t, drone))
    t, drone, pos, up = t[order], drone[order], pos[order], up[order]
    # a stretch: consecutive airborne rows of one drone, none left out between them
    new = np.ones(len(t), dtype=bool)
    new[1:] = (drone[1:] != drone[:-1]) | ~up[:-1]
    starts = np.flatnonzero(up & new)
    stretches = []
    for a in starts:
        b = a
        while b + 1 < len(t) and up[b + 1] and drone[b + 1] == drone[a]:
            b += 1
        if b > a:
            stretches.append((a, b + 1))
    ne = np.concatenate([g[1] for g in ground] + [pos[a:b, :2] for a, b in stretches])
    alts = np.concatenate([np.zeros(len(g[1])) for g in ground]
                          + [pos[a:b, 2] for a, b in stretches])
    lonlat = np.round(ned_to_lonlat(ne[:, 0], ne[:, 1], -alts, home)[:, :2], 7)
    features = _ground_features(ground, lonlat)
    i = sum(len(pts) for _, pts in ground)
    for a, b in stretches:
        ll = np.column_stack([lonlat[i:i + b - a], np.round(pos[a:b, 2], 2)]).tolist()
        i += b - a
        features.append({"type": "Feature",
                         "geometry": {"type": "LineString", "coordinates": ll},
                         "properties": {"kind": "track", "drone": int(drone[a]),
                                        "t0_s": float(t[a]), "t1_s": float(t[b - 1])}})
    return {"type": "FeatureCollection", "features": features}


def _ground(s) -> list[tuple[dict, np.ndarray]]:
    """(properties, (north, east) points) of the airports, gates, runways and no-fly
    zones."""
    ground: list[tuple[dict, np.ndarray]] = []
    for a in s.airports:
        ground.append(({"kind": "airport", "id": a.id}, np.array([[a.north, a.east]])))
    for a in s.airports:
        for g in (0, 1):
            ground.append(({"kind": "gate", "airport": a.id, "gate": g},
                           gate_position(a, g)[None]))
    for a in s.airports:
        for kind, rwy in (("landing", a.landing), ("takeoff", a.takeoff)):
            ground.append(({"kind": kind, "airport": a.id, "heading_deg": rwy.heading_deg,
                            "length_m": rwy.length}, np.array(runway_ends(a, rwy))))
    for z in s.no_fly_zones:  # closed rings, anticlockwise seen from above (RFC 7946)
        ring = np.array([*z.points, z.points[0]], dtype=float)
        n, e = ring[:, 0], ring[:, 1]
        if np.sum(e[:-1] * n[1:] - e[1:] * n[:-1]) < 0:  # clockwise in (east, north)
            ring = ring[::-1]
        ground.append(({"kind": "no_fly_zone", "name": z.name}, ring))
    return ground


def _ground_features(ground, lonlat: np.ndarray) -> list[dict]:
    """The ground features, their points taken in order from the start of ``lonlat``."""
    features = []
    i = 0
    for props, pts in ground:
        ll = lonlat[i:i + len(pts)].tolist()
        i += len(pts)
        if props["kind"] == "no_fly_zone":
            geom = {"type": "Polygon", "coordinates": [ll]}
        elif len(pts) == 1:
            geom = {"type": "Point", "coordinates": ll[0]}
        else:
            geom = {"type": "LineString", "coordinates": ll}
        features.append({"type": "Feature", "geometry": geom, "properties": props})
    return features


def _alts(ground, flights) -> np.ndarray:
    return np.concatenate([np.zeros(len(pts)) for _, pts in ground]
                          + [pos[:, 2] for _, pos in flights])


# -- pictures -----------------------------------------------------------------------
def plot_map(sim: Simulation, path: str | Path, *, dpi: int = 150) -> Path:
    """``map.png``: runways (landing dark, take-off light), gates, airports, no-fly zones
    (hatched, named), and the airborne tracks coloured by drone (a legend up to 10
    drones, else a colour bar); metres north and east of the home, true proportions."""
    import shapely
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.patches import Polygon

    from skyroute.fleet.report import flights_flown
    from skyroute.io.plot import (
        legend_outside,
        new_figure,
        place_labels,
        save_figure,
        set_title,
    )

    s = sim.scenario
    fig, ax = new_figure((9, 8))
    n = s.drones
    cmap = colormaps["tab10" if n <= 10 else "viridis"]
    colour = (lambda d: cmap(d % 10)) if n <= 10 else (lambda d: cmap(d / max(n - 1, 1)))
    lines: dict[int, list[np.ndarray]] = {}
    for f in sim.flights:
        _, pos = airborne_samples(f.plan, 1.0, sim.horizon)
        if len(pos) >= 2:
            lines.setdefault(f.plan.drone, []).append(pos[:, [1, 0]])
    for d in sorted(lines):
        ax.add_collection(LineCollection(lines[d], colors=[colour(d)], linewidths=0.7,
                                         alpha=0.6, zorder=2,
                                         label=f"drone {d}" if n <= 10 else None))
    for kind, colour_rwy, lw in (("landing", "0.15", 4.0), ("takeoff", "0.6", 4.0)):
        for k, a in enumerate(s.airports):
            ends = np.array(runway_ends(a, getattr(a, kind)))
            ax.plot(ends[:, 1], ends[:, 0], "-", color=colour_rwy, lw=lw,
                    solid_capstyle="butt", zorder=3,
                    label=f"{kind.replace('takeoff', 'take-off')} runway" if k == 0 else None)
    gates = np.array([gate_position(a, g) for a in s.airports for g in (0, 1)])
    ax.plot(gates[:, 1], gates[:, 0], "s", color="tab:red", ms=3, zorder=4, label="gates")
    for k, z in enumerate(s.no_fly_zones):  # under the tracks, which go round them
        ax.add_patch(Polygon([(e, n) for n, e in z.points], closed=True, zorder=1,
                             facecolor=(0.7, 0.15, 0.12, 0.15), edgecolor=(0.7, 0.15, 0.12),
                             hatch="//", lw=1.0, gid=f"no_fly_zone {z.name}",
                             label="no-fly zone" if k == 0 else None))
        c = shapely.Polygon([(e, n) for n, e in z.points]).representative_point()
        ax.text(c.x, c.y, z.name, ha="center", va="center", fontsize=8, style="italic",
                color=(0.55, 0.1, 0.08), zorder=1)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    # the flights the report counts (a run also holds flights planned past its end)
    set_title(ax, [*_settings(sim), f"{len(flights_flown(sim))} flights"])
    if n > 10:
        sm = ScalarMappable(cmap=cmap, norm=Normalize(0, n - 1))
        fig.colorbar(sm, ax=ax, label="drone", orientation="horizontal", shrink=0.6,
                     pad=0.08, aspect=40)
    legend_outside(ax)
    # airport names last, each where it covers no other name (30 airports piled up)
    place_labels(ax, [(a.east, a.north) for a in s.airports], [a.id for a in s.airports],
                 avoid=gates[:, ::-1], fontsize=11 if len(s.airports) <= 12 else 8,
                 fontweight="bold")
    return save_figure(fig, path, dpi=dpi)


def plot_timeline(sim: Simulation, path: str | Path, *, dpi: int = 150) -> Path:
    """``timeline.png``: packages waiting (spawned, not picked up), in flight (picked
    up, not handed over) and delivered (cumulative) over time; below, each loiter circle
    (a landing refused) by airport; the warm-up window shaded on both."""
    from skyroute.fleet.report import window_counts
    from skyroute.io.plot import new_figure, save_figure, set_title

    H = sim.horizon
    st = sim.stream
    minutes = H <= 3 * 3600
    unit, scale = ("min", 60.0) if minutes else ("h", 3600.0)
    t = np.linspace(0.0, H, 2001)

    def count(times) -> np.ndarray:
        x = np.sort(times[times <= H])  # NaN sorts last and fails <= H
        return np.searchsorted(x, t, side="right")

    spawned = count(st.t[st.t < H])
    picked, delivered = count(sim.pickup), count(sim.delivered)
    fig, (top, low) = new_figure((10, 6.5), 2, 1, sharex=True,
                                 gridspec_kw={"height_ratios": [3, 1.3]})
    x = t / scale
    top.step(x, spawned - picked, where="post", color="tab:orange", label="waiting")
    top.step(x, picked - delivered, where="post", color="tab:blue", label="in flight")
    top.step(x, delivered, where="post", color="tab:green", label="delivered (cumulative)")
    top.set_ylabel("packages")
    top.set_ylim(bottom=0)
    ids = [a.id for a in sim.scenario.airports]
    row = {a: k for k, a in enumerate(ids)}
    denied = np.array([(e["t"], row[e["airport"]]) for e in sim.events
                       if e["kind"] == "landing_denied"]).reshape(-1, 2)
    if len(ids) <= _BY_AIRPORT:  # one row of markers per airport
        low.plot(denied[:, 0] / scale, denied[:, 1], "o", color="tab:red", ms=5,
                 alpha=0.7)
        low.set_yticks(range(len(ids)), ids)
        low.set_ylim(-0.7, len(ids) - 0.3)
        low.set_ylabel("airport")
    else:  # too many airports to name: circles per time bin
        bins = np.linspace(0.0, H / scale, 61)
        low.hist(denied[:, 0] / scale, bins=bins, color="tab:red", alpha=0.8)
        low.set_ylabel(f"per {_duration(H / 60)}")
    set_title(low, [f"loiter circles (landing refused): {len(denied)}"], fontsize=9)
    low.set_xlabel(f"time ({unit})")
    for ax in (top, low):
        ax.axvspan(0, WARMUP_SHARE * H / scale, color="0.88", zorder=0,
                   label="warm-up (not in rates)")
        ax.grid(alpha=0.3)
        ax.set_xlim(0, H / scale)
    top.legend(loc="upper left", fontsize=8)
    # the report's numbers first (the measured window, as the command's table prints
    # them), then the whole run that the curves show
    offered, done = window_counts(sim)
    set_title(top, [*_settings(sim), f"{done} of {offered} packages delivered after the "
                                     f"{_duration(WARMUP_SHARE * H)} warm-up; "
                                     f"{int(delivered[-1])} of {int(spawned[-1])} in the whole "
                                     "run"])
    return save_figure(fig, path, dpi=dpi)


def _settings(sim: Simulation) -> list[str]:
    """The title parts that say which run a picture shows."""
    return [f"{sim.scenario.name}: {sim.scheduler} dispatch", f"{sim.airspace} airspace",
            f"{sim.hours:g} h", f"seed {sim.seed}"]


def _duration(seconds: float) -> str:
    """``4 min``, ``1.5 h``, ``30 s``: a span in the unit that reads best."""
    if seconds >= 2 * 3600:
        return f"{seconds / 3600:.3g} h"
    if seconds >= 120:
        return f"{seconds / 60:.3g} min"
    return f"{seconds:.3g} s"
