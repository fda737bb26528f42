"""An independent audit of what ``skyroute fleet simulate --out`` writes.

Written from the rules of docs/fleet.md alone, reading only the run's files (and the
scenario's documented fields for the runways' geometry); it shares no code with the
simulator, its reservations or its separation checker (``skyroute.fleet``), so it can
disagree with them. :func:`audit` returns the problems it finds, one line each, and the
numbers it recomputed; an empty list means the files keep every rule checked:

- tracks: times rise per drone; no drone moves faster than it can (cruise speed);
  ground phases at altitude 0; a drone reappears where it parked;
- separation: no two airborne drones closer than ``sep_horizontal`` horizontally and
  ``sep_vertical`` vertically at once, between the samples of ``tracks.csv`` too (each
  drone moves on the straight line between two samples; the exact closest approach of
  two such lines), and the report's closest pair no farther than the files show;
- events: per drone, take-off, landing requests (a refusal, then one loiter circle,
  then a new request), the permission, touchdown where it was granted; the approach in
  the tracks only after the permission;
- one drone at a time on each take-off runway (ground samples on its centre line, from
  the airport's position to lift-off), in each airport's landing block (permission to
  back at the airport's position), at each gate (the ``handover_seconds`` before a
  ``pickup`` or ``delivered`` event); ground movements the docs leave unbooked are
  noted (:meth:`Audit.note`), not problems;
- packages: each delivered package assigned, picked up at its origin gate and handed
  over at its destination gate by one drone, which flew it there without another
  landing, one package at a time per drone; ``packages.csv`` agrees with the events;
- the report's counts, rates, percentiles and capacity numbers recomputed from
  ``events.jsonl`` and ``packages.csv`` as docs/fleet.md defines them.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
from collections import defaultdict
from pathlib import Path

import numpy as np
from pyproj import Transformer

AIRBORNE = ("climb", "cruise", "loiter", "approach")
GROUND = ("taxi", "takeoff", "landing", "rollout")
WARMUP_SHARE = 0.1  # docs/fleet.md: "the first 10% of the horizon is warm-up"
MS = 1e-3  # times in the files are written to the millisecond
ON_LINE = 0.5  # metres from a runway's centre line that count as on it


def read_run(folder: str | Path) -> dict:
    """The files of one run: ``report``, ``events`` (list of dicts), ``tracks`` (columns),
    ``packages`` (list of dicts, strings as written), ``geojson``."""
    d = Path(folder)
    report = json.loads((d / "report.json").read_text())
    events = [json.loads(line) for line in (d / "events.jsonl").read_text().splitlines()]
    with open(d / "tracks.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t", "drone", "north", "east", "alt", "phase"], rows[0]
    body = rows[1:]
    tracks = {"t": np.array([float(r[0]) for r in body]),
              "drone": np.array([int(r[1]) for r in body], dtype=np.int64),
              "pos": np.array([[float(x) for x in r[2:5]] for r in body]).reshape(-1, 3),
              "phase": np.array([r[5] for r in body], dtype=object)}
    with open(d / "packages.csv", newline="") as fh:
        packages = list(csv.DictReader(fh))
    geojson = json.loads((d / "fleet.geojson").read_text())
    return {"report": report, "events": events, "tracks": tracks, "packages": packages,
            "geojson": geojson}


def _opt(x: str) -> float | None:
    return float(x) if x != "" else None


class Audit:
    """One run's files checked against ``scenario`` (the airports' runways, gate width,
    drone speeds, handover time; the separation minima come from the report)."""

    def __init__(self, folder, scenario, *, step: float = 1.0, hours: float | None = None):
        self.run = read_run(folder)
        self.s = scenario
        self.rep = self.run["report"]
        st = self.rep["settings"]
        self.H = (hours if hours is not None else st["hours"]) * 3600.0
        self.warmup = WARMUP_SHARE * self.H
        self.sh, self.sv = st["sep_horizontal"], st["sep_vertical"]
        self.step = step
        self.problems: list[str] = []
        self.notes: list[str] = []
        self.numbers: dict = {}
        self.events = self.run["events"]
        self.by_drone: dict[int, list[dict]] = defaultdict(list)
        for e in self.events:
            if "drone" in e:
                self.by_drone[e["drone"]].append(e)

    def bad(self, text: str) -> None:
        self.problems.append(text)

    def note(self, text: str) -> None:
        """What docs/fleet.md leaves to the ground ("timed but not deconflicted beyond
        the runway and gate bookings"): seen, but no problem. The default gates stand on
        the landing runway's line when the runways cross at right angles (every
        generated scenario), so the taxi between a gate and the airport's position runs
        on it, unbooked; a drone taxiing in crosses the take-off runway at the position,
        unbooked."""
        self.notes.append(text)

    # ---------------------------------------------------------------- geometry
    def runway(self, airport, kind):
        """(centre, unit direction, half length) of an airport's landing or take-off
        runway: it passes through the airport's position (docs: centred there, which
        fleet.geojson shows) on its compass heading."""
        rw = getattr(airport, kind)
        h = math.radians(rw.heading_deg)
        return (np.array([airport.north, airport.east]), np.array([math.cos(h), math.sin(h)]),
                rw.length / 2)

    def gates_from_geojson(self) -> dict[tuple[str, int], np.ndarray]:
        s = self.s
        to_ne = Transformer.from_crs(
            "EPSG:4326", f"+proj=aeqd +lat_0={s.home_lat} +lon_0={s.home_lon} +units=m",
            always_xy=True)
        out = {}
        for f in self.run["geojson"]["features"]:
            p = f["properties"]
            if p.get("kind") == "gate":
                x, y = to_ne.transform(*f["geometry"]["coordinates"][:2])
                out[(p["airport"], int(p["gate"]))] = np.array([y, x])
        return out

    # ---------------------------------------------------------------- checks
    def check(self) -> list[str]:
        self.check_tracks()
        self.check_separation()
        self.check_drone_events()
        self.check_runways()
        self.check_gates()
        self.check_packages()
        self.check_report()
        return self.problems

    def check_tracks(self) -> None:
        tr = self.run["tracks"]
        t, drone, pos, phase = tr["t"], tr["drone"], tr["pos"], tr["phase"]
        if len(t) and not (t[1:] >= t[:-1]).all():
            self.bad("tracks.csv: rows are not sorted by time")
        if len(t) and (t.max() > self.H + MS or t.min() < 0):
            self.bad("tracks.csv: a row outside the run")
        ground = np.isin(phase, GROUND)
        if (pos[ground, 2] != 0).any():
            self.bad("tracks.csv: a ground phase above altitude 0")
        if (pos[~ground, 2] < 0).any():
            self.bad("tracks.csv: an airborne row below the ground")
        unknown = set(phase) - set(AIRBORNE) - set(GROUND)
        if unknown:
            self.bad(f"tracks.csv: unknown phases {sorted(unknown)}")
        vmax = self.s.drone.cruise_speed
        # the apron: between an airport's two gates, where fleet.geojson puts them (an
        # airport's `gates` may place them farther apart than gate_width)
        gates = self.gates_from_geojson()
        gate_gap = max([float(np.hypot(*(gates[(a.id, 0)] - gates[(a.id, 1)])))
                        for a in self.s.airports if (a.id, 0) in gates and (a.id, 1) in gates]
                       + [a.gate_width for a in self.s.airports])
        apron = max(gate_gap, 30.0) + 2 * self.step + 0.01
        self.series = {}
        for d in np.unique(drone):
            m = drone == d
            td, pd, ph = t[m], pos[m], phase[m]
            if not (np.diff(td) > 0).all():
                self.bad(f"tracks.csv: drone {d}'s times do not rise")
                continue
            dt = np.diff(td)
            dist = np.linalg.norm(np.diff(pd, axis=0), axis=1)
            joined = dt <= self.step * (1 + 1e-9)
            # a drone leaving by the other gate the instant it arrived (no hand-over
            # time) crosses the untracked apron between two taxi rows a step apart
            crossed = (ph[:-1] == "taxi") & (ph[1:] == "taxi") & (dist <= apron)
            fast = joined & (dist > vmax * dt + 0.01) & ~crossed
            if fast.any():
                k = np.flatnonzero(fast)[0]
                self.bad(f"tracks.csv: drone {d} moves {dist[k]:.1f} m in {dt[k]:g} s at "
                         f"t={td[k]:g}")
            # parked between two flights (no rows): it leaves from where it arrived
            # (the other gate at most, over the apron)
            jump = ~joined & (dist > apron)
            if jump.any():
                k = np.flatnonzero(jump)[0]
                self.bad(f"tracks.csv: drone {d} parked at t={td[k]:g} and reappeared "
                         f"{dist[k]:.0f} m away at t={td[k + 1]:g}")
            self.series[int(d)] = (td, pd, ph)

    # -- separation ------------------------------------------------------------
    def _grid(self):
        """Positions (drones, K, 3) on the time grid k * step (NaN where a drone has no
        row) and the phase of each sample ('' where none)."""
        tr = self.run["tracks"]
        n = self.s.drones
        K = round(self.H / self.step) + 1
        P = np.full((n, K, 3), np.nan)
        ph = np.full((n, K), "", dtype=object)
        k = np.rint(tr["t"] / self.step).astype(np.int64)
        P[tr["drone"], k] = tr["pos"]
        ph[tr["drone"], k] = tr["phase"]
        return P, ph

    def _segment_error(self, ph: np.ndarray):
        """How far (horizontally, vertically) a drone can be, within each step, from the
        straight line between its two samples: 0 on a climb or an approach (one
        straight piece each); the chord of a turn on a cruise or a loiter (level, turns
        of ``turn_radius``); half a step at full speed where the phase changes between
        the samples (a kink anywhere in the step)."""
        d = self.s.drone
        v, dt = d.cruise_speed, self.step
        vz = v * math.sin(math.radians(max(d.climb_angle_deg, d.glide_angle_deg)))
        chord = d.turn_radius * (1 - math.cos(min(v * dt / (2 * d.turn_radius), math.pi / 2)))
        a, b = ph[:, :-1], ph[:, 1:]
        same = a == b
        straight = same & np.isin(a, ("climb", "approach"))
        level = same & np.isin(a, ("cruise", "loiter"))
        eh = np.where(straight, 0.0, np.where(level, chord, v * dt / 2))
        ev = np.where(straight | level, 0.0, vz * dt / 2)
        return eh + 0.002, ev + 0.002  # and millimetres of rounding

    def check_separation(self) -> None:
        """At the samples (exact positions): the least horizontal distance of airborne
        pairs closer than sep_v vertically and the least vertical distance of pairs
        closer than sep_h horizontally, which the report (every instant, flights past the
        end too) must not exceed. Between samples: a loss wherever the straight lines
        between samples come closer than the minima by more than the drones can be off
        those lines (:meth:`_segment_error`)."""
        P, ph = self._grid()
        air = np.isin(ph, AIRBORNE)
        eh, ev = self._segment_error(ph)
        n = P.shape[0]
        sh, sv = self.sh, self.sv
        best_h = best_v = math.inf
        losses = []
        for i in range(n):
            for j in range(i + 1, n):
                both = np.flatnonzero(air[i] & air[j])
                if len(both):
                    r = P[i, both] - P[j, both]
                    h, v = np.hypot(r[:, 0], r[:, 1]), np.abs(r[:, 2])
                    if (v < sv).any():
                        best_h = min(best_h, float(h[v < sv].min()))
                    if (h < sh).any():
                        best_v = min(best_v, float(v[h < sh].min()))
                    lost = (h < sh) & (v < sv)
                    if lost.any():
                        losses.append((i, j, both[lost][0] * self.step, float(h[lost][0])))
                # a segment [k, k+1] is airborne when either end is (lift-off and
                # touchdown fall between samples; the error bound covers the ground part)
                seg = ((air[i, :-1] | air[i, 1:]) & (air[j, :-1] | air[j, 1:])
                       & ~np.isnan(P[i, :-1, 0]) & ~np.isnan(P[i, 1:, 0])
                       & ~np.isnan(P[j, :-1, 0]) & ~np.isnan(P[j, 1:, 0]))
                ks = np.flatnonzero(seg)
                if not len(ks):
                    continue
                h, _ = _segment_minima(P[i, ks] - P[j, ks], P[i, ks + 1] - P[j, ks + 1],
                                       sh - eh[i, ks] - eh[j, ks], sv - ev[i, ks] - ev[j, ks])
                lost = h < sh - eh[i, ks] - eh[j, ks]
                if lost.any():
                    k = np.flatnonzero(lost)[0]
                    losses.append((i, j, ks[k] * self.step, float(h[k])))
        self.numbers["min_horizontal_m"] = None if math.isinf(best_h) else best_h
        self.numbers["min_vertical_m"] = None if math.isinf(best_v) else best_v
        for i, j, t, h in losses[:3]:
            self.bad(f"separation: drones {i} and {j} {h:.1f} m apart horizontally, within "
                     f"{sv:g} m vertically, at t={t:g} s or in the step after")
        rh, rv = self.rep["min_horizontal_m"], self.rep["min_vertical_m"]
        for name, mine, got in (("min_horizontal_m", best_h, rh), ("min_vertical_m", best_v,
                                                                   rv)):
            if mine < math.inf and (got is None or got > mine + 0.002):
                self.bad(f"report.json: {name} {got}, but the tracks show {mine:.3f} m")

    # -- each drone's event log ------------------------------------------------
    def check_drone_events(self) -> None:
        loiter_s = 2 * math.pi * self.s.drone.turn_radius / self.s.drone.cruise_speed
        self.landings = []  # (airport, drone, granted, touchdown)
        self.takeoffs = []  # (airport, drone, t)
        for d, evs in sorted(self.by_drone.items()):
            ts = [e["t"] for e in evs]
            if ts != sorted(ts):
                self.bad(f"events.jsonl: drone {d}'s times go back")
            where = None  # airport the drone is at; None before its first take-off
            flying = None  # (origin, package) while airborne
            request = None  # (airport, gate, t) of the pending request
            granted = None
            for e in evs:
                k = e["kind"]
                if k == "takeoff":
                    if flying is not None:
                        self.bad(f"events: drone {d} takes off at {e['t']} while flying")
                    if where is not None and e["airport"] != where:
                        self.bad(f"events: drone {d} takes off at {e['airport']} at "
                                 f"{e['t']} but landed at {where}")
                    flying = (e["airport"], e.get("package"), e["t"])
                    self.takeoffs.append((e["airport"], d, e["t"]))
                    request = granted = None
                elif k in ("landing_request", "landing_denied", "landing_granted"):
                    if flying is None:
                        self.bad(f"events: drone {d} {k} at {e['t']} on the ground")
                        continue
                    if e.get("package") != flying[1]:
                        self.bad(f"events: drone {d} {k} at {e['t']} names package "
                                 f"{e.get('package')}, took off with {flying[1]}")
                    if k == "landing_request":
                        if request is not None and request[3] != "denied":
                            self.bad(f"events: drone {d} asks again at {e['t']} unanswered")
                        if request is not None and abs(e["t"] - request[2] - loiter_s) > 2 * MS:
                            self.bad(f"events: drone {d} asks again at {e['t']}, "
                                     f"{e['t'] - request[2]:.3f} s after a refusal, not "
                                     f"one loiter circle ({loiter_s:.3f} s)")
                        if request is not None and (e["airport"], e["gate"]) != request[:2]:
                            self.bad(f"events: drone {d} changes its destination at {e['t']}")
                        request = (e["airport"], e["gate"], e["t"], "asked")
                    else:
                        if request is None or request[3] != "asked" or (
                                e["airport"], e["gate"]) != request[:2] or e["t"] != request[2]:
                            self.bad(f"events: drone {d} {k} at {e['t']} answers no request")
                        if request is not None:
                            request = (*request[:3], "denied" if k == "landing_denied"
                                       else "granted")
                        if k == "landing_granted":
                            granted = (e["airport"], e["gate"], e["t"])
                elif k == "touchdown":
                    if granted is None or granted[0] != e["airport"]:
                        self.bad(f"events: drone {d} touches down at {e['airport']} at "
                                 f"{e['t']} without permission to land there")
                    else:
                        self.landings.append((e["airport"], d, granted[2], e["t"], granted[1]))
                        self._approach_after_permission(d, flying[2], granted[2], e["t"])
                    where, flying, request, granted = e["airport"], None, None, None
                elif k in ("pickup", "delivered"):
                    if flying is not None:
                        self.bad(f"events: drone {d} {k} at {e['t']} while airborne")
                    if where is not None and e["airport"] != where:
                        self.bad(f"events: drone {d} {k} at {e['airport']} at {e['t']} but "
                                 f"it is at {where}")
                    where = e["airport"]

    def _approach_after_permission(self, d, t_off, t_granted, t_down) -> None:
        if d not in self.series:
            return
        td, _, ph = self.series[d]
        m = (td >= t_off - MS) & (td <= t_down + MS)
        early = m & (ph == "approach") & (td < t_granted - MS)
        if early.any():
            self.bad(f"tracks: drone {d} on approach at t={td[early][0]:g} before its "
                     f"landing permission at {t_granted}")
        late_loiter = m & (ph == "loiter") & (td > t_granted + MS)
        if late_loiter.any():
            self.bad(f"tracks: drone {d} loiters at t={td[late_loiter][0]:g} after its "
                     f"landing permission at {t_granted}")

    # -- runways ---------------------------------------------------------------
    def _along(self, airport, kind, ne: np.ndarray):
        """(metres along the runway from the airport's position, on the runway's line
        and length) of points ``ne``."""
        c, u, half = self.runway(airport, kind)
        r = ne - c
        along = r @ u
        across = np.abs(r[:, 0] * u[1] - r[:, 1] * u[0])
        return along, (across <= ON_LINE) & (np.abs(along) <= half + ON_LINE)

    def _arriving(self) -> np.ndarray:
        """Per track row: whether the drone is on the ground after a touchdown (roll-out,
        taxi in) rather than before a take-off (taxi out, roll)."""
        tr = self.run["tracks"]
        out = np.zeros(len(tr["t"]), dtype=bool)
        for d in np.unique(tr["drone"]):
            m = np.flatnonzero(tr["drone"] == d)
            marks = sorted((e["t"], e["kind"]) for e in self.by_drone.get(int(d), [])
                           if e["kind"] in ("takeoff", "touchdown"))
            ts = np.array([x[0] for x in marks])
            down = np.array([x[1] == "touchdown" for x in marks])
            k = np.searchsorted(ts, tr["t"][m], side="right") - 1
            out[m] = (k >= 0) & down[np.maximum(k, 0)] if len(ts) else False
        return out

    def check_runways(self) -> None:
        """docs/fleet.md's airport manager: take-offs hold the take-off runway from the
        airport's position to lift-off, one at a time; a landing holds the landing
        runway from its permission until the drone has rolled out and taxied back to the
        airport's position, one at a time, and no other drone taxis on the part it
        uses (threshold to position) meanwhile."""
        tr = self.run["tracks"]
        t, d, ne = tr["t"], tr["drone"], tr["pos"][:, :2]
        ground = np.isin(tr["phase"], GROUND)
        arriving = self._arriving()
        for a in self.s.airports:
            along, on = self._along(a, "takeoff", ne)
            dep = ground & on & ~arriving
            self._one_at_a_time(t[dep], d[dep], f"{a.id}'s take-off runway")
            cross = ground & on & arriving
            both = np.isin(t[cross], t[dep])
            for k in np.flatnonzero(both)[:1]:
                self.note(f"runway: drone {d[cross][k]}, taxiing in, crosses {a.id}'s "
                          f"take-off runway at t={t[cross][k]:g} while another drone takes "
                          "off")
            along, on = self._along(a, "landing", ne)
            used = ground & on & (along <= ON_LINE)  # threshold to the position
            blocks = []
            for ap, dr, t_granted, t_down, _gate in self.landings:
                if ap != a.id:
                    continue
                # this flight's rows from touchdown on (until the drone parks: a gap)
                m = np.flatnonzero((d == dr) & (t >= t_down))
                if len(m):
                    gap = np.flatnonzero(np.diff(t[m]) > self.step * (1 + 1e-9))
                    m = m[:gap[0] + 1] if len(gap) else m
                # the first sample at or past the airport's position: along it, or
                # turned back towards a gate behind it, or off the runway
                back = np.zeros(len(m), dtype=bool)
                back[1:] = np.diff(along[m]) < 0
                past = (along[m] >= -ON_LINE) | ~on[m] | back
                end = (float(t[m][past][0]) if past.any() else
                       float(t[m][-1]) if len(m) else t_down)
                blocks.append((t_granted, end, dr))
                # anyone else taxiing on the part the landing uses meanwhile
                other = used & (d != dr) & (t >= t_granted) & (t <= end - self.step)
                if other.any():
                    k = np.flatnonzero(other)[0]
                    self.note(f"runway: drone {d[k]} on {a.id}'s landing runway at t={t[k]:g} "
                             f"while drone {dr} lands (cleared {t_granted})")
            blocks.sort()
            for (g0, e0, d0), (g1, _e1, d1) in itertools.pairwise(blocks):
                if g1 < e0 - self.step - MS:  # the end is known to a step
                    self.bad(f"landing: drone {d1} cleared to land at {a.id} at {g1} while "
                             f"drone {d0} (cleared {g0}) still lands or rolls until about "
                             f"{e0:g}")

    def _one_at_a_time(self, t, d, what) -> None:
        order = np.lexsort((d, t))
        t, d = t[order], d[order]
        same = np.flatnonzero((t[1:] == t[:-1]) & (d[1:] != d[:-1]))
        for k in same[:1]:
            self.bad(f"runway: drones {d[k]} and {d[k + 1]} both on {what} at t={t[k]:g}")

    # -- gates -----------------------------------------------------------------
    def check_gates(self) -> None:
        H = self.s.handover_seconds
        windows = defaultdict(list)
        for e in self.events:
            if e["kind"] in ("pickup", "delivered"):
                windows[(e["airport"], e["gate"])].append((e["t"] - H, e["t"], e["drone"],
                                                          e["kind"], e["package"]))
        for key, ws in windows.items():
            ws.sort()
            for w0, w1 in itertools.pairwise(ws):
                if w1[2] != w0[2] and w1[0] < w0[1] - MS:
                    self.bad(f"gate {key[0]}{key[1]}: drone {w1[2]} ({w1[3]} {w1[4]}) from "
                             f"{w1[0]:.3f} while drone {w0[2]} ({w0[3]} {w0[4]}) holds it "
                             f"until {w0[1]:.3f}")
        # the drone is at that gate: its track ends there before a hand-over window
        # or starts there after it
        gates = self.gates_from_geojson()
        self.numbers["gates"] = gates
        reach = self.s.drone.taxi_gate_speed * self.step + 0.01
        for e in self.events:
            if e["kind"] not in ("pickup", "delivered") or e["drone"] not in self.series:
                continue
            td, pd, _ = self.series[e["drone"]]
            g = gates[(e["airport"], e["gate"])]
            if e["kind"] == "delivered":
                k = np.searchsorted(td, e["t"] - H + MS, side="right") - 1
            else:
                k = np.searchsorted(td, e["t"] - MS, side="left")
            if not 0 <= k < len(td) or abs(td[k] - (e["t"] - H if e["kind"] == "delivered"
                                                    else e["t"])) > self.step:
                continue  # a hand-over at the edge of the run, or at a step's rows
            dist = float(np.hypot(*(pd[k, :2] - g)))
            if e["kind"] == "pickup" and k + 1 < len(td) and td[k + 1] - td[k] <= self.step:
                # with no hand-over time a drone leaves the instant it arrived: the row
                # of that instant may show it arriving at the other gate
                dist = min(dist, float(np.hypot(*(pd[k + 1, :2] - g))))
            if dist > reach:
                self.bad(f"gate: drone {e['drone']} {e['kind']} package {e['package']} at "
                         f"{e['airport']}{e['gate']} at {e['t']} but its track is "
                         f"{dist:.1f} m from the gate at t={td[k]:g}")

    # -- packages --------------------------------------------------------------
    def check_packages(self) -> None:
        per = defaultdict(list)
        for e in self.events:
            if "package" in e and e["kind"] in ("spawn", "assign", "pickup", "delivered"):
                per[e["package"]].append(e)
        rows = {int(r["id"]): r for r in self.run["packages"]}
        lost = 0
        carrying = defaultdict(list)  # drone -> [(pickup, delivered)]
        for p, r in rows.items():
            evs = per.get(p, [])
            kinds = [e["kind"] for e in evs]
            ok = bool(kinds) and kinds[0] == "spawn" and kinds == [
                "spawn", "assign", "pickup", "delivered"][:len(kinds)]
            if not ok:
                lost += 1
                self.bad(f"package {p}: events {kinds}")
                continue
            sp = evs[0]
            if (sp["airport"], sp["gate"]) != (r["from_airport"], int(r["from_gate"])):
                self.bad(f"package {p}: spawns at {sp['airport']}{sp['gate']}, "
                         f"packages.csv says {r['from_airport']}{r['from_gate']}")
            times = {e["kind"]: e["t"] for e in evs}
            for kind, col in (("spawn", "spawn_s"), ("assign", "assigned_s"),
                              ("pickup", "pickup_s"), ("delivered", "delivered_s")):
                x = _opt(r[col])
                if (x is None) != (kind not in times) or (
                        x is not None and abs(x - times[kind]) > MS / 2):
                    self.bad(f"package {p}: packages.csv {col}={r[col]!r}, events "
                             f"{times.get(kind)}")
            if not all(a <= b for a, b in zip([e["t"] for e in evs],
                                              [e["t"] for e in evs[1:]], strict=False)):
                self.bad(f"package {p}: events out of time order")
            drones = {e["drone"] for e in evs if "drone" in e}
            if len(drones) > 1:
                self.bad(f"package {p}: handled by drones {sorted(drones)}")
            if drones and r["drone"] != str(next(iter(drones))):
                self.bad(f"package {p}: packages.csv drone {r['drone']!r}, events "
                         f"{sorted(drones)}")
            state = ["waiting", "assigned", "carried", "delivered"][len(kinds) - 1]
            if r["state"] != state:
                self.bad(f"package {p}: state {r['state']}, events say {state}")
            if "pickup" in times:
                e = evs[2]
                if (e["airport"], e["gate"]) != (r["from_airport"], int(r["from_gate"])):
                    lost += 1
                    self.bad(f"package {p}: picked up at {e['airport']}{e['gate']}, not "
                             f"at its origin {r['from_airport']}{r['from_gate']}")
            if "delivered" in times:
                e = evs[3]
                if (e["airport"], e["gate"]) != (r["to_airport"], int(r["to_gate"])):
                    lost += 1
                    self.bad(f"package {p}: delivered at {e['airport']}{e['gate']}, not "
                             f"at its destination {r['to_airport']}{r['to_gate']}")
                d = e["drone"]
                carrying[d].append((times["pickup"], times["delivered"], p))
                self._flown_by(d, p, times["pickup"], times["delivered"], r)
        for d, spans in carrying.items():
            spans.sort()
            for a, b in itertools.pairwise(spans):
                if b[0] < a[1]:
                    self.bad(f"drone {d} carries packages {a[2]} and {b[2]} at once")
        self.numbers["lost"] = lost
        ids = sorted(rows)
        spawned = sorted(e["package"] for e in self.events if e["kind"] == "spawn")
        if ids != spawned:
            self.bad("packages.csv rows are not the spawned packages")

    def _flown_by(self, d, p, t_pick, t_del, row) -> None:
        """Between pickup and hand-over: one take-off from the origin with the package
        and one touchdown at the destination, cleared for the destination gate."""
        evs = [e for e in self.by_drone[d] if t_pick <= e["t"] <= t_del]
        offs = [e for e in evs if e["kind"] == "takeoff"]
        downs = [e for e in evs if e["kind"] == "touchdown"]
        grants = [e for e in evs if e["kind"] == "landing_granted"]
        if len(offs) != 1 or len(downs) != 1 or len(grants) != 1:
            self.bad(f"package {p}: drone {d} took off {len(offs)} and landed {len(downs)} "
                     "times carrying it")
            return
        if offs[0]["airport"] != row["from_airport"] or offs[0].get("package") != p:
            self.bad(f"package {p}: carried off {offs[0]['airport']} on flight of "
                     f"package {offs[0].get('package')}")
        if downs[0]["airport"] != row["to_airport"] or grants[0]["gate"] != int(row["to_gate"]):
            self.bad(f"package {p}: landed at {downs[0]['airport']} gate "
                     f"{grants[0]['gate']}, not {row['to_airport']}{row['to_gate']}")

    # -- the report's numbers ---------------------------------------------------
    def check_report(self) -> None:
        rep, H, w = self.rep, self.H, self.warmup
        s = self.s
        pk = self.run["packages"]
        spawn = np.array([float(r["spawn_s"]) for r in pk])
        deliv, pick, assigned = (np.array([np.nan if r[c] == "" else float(r[c]) for r in pk])
                                 for c in ("delivered_s", "pickup_s", "assigned_s"))
        window_h = (H - w) / 3600.0
        offered = int(((spawn >= w) & (spawn <= H)).sum())
        done = (deliv >= w) & (deliv <= H)
        delivered = int(done.sum())
        times = (deliv - spawn)[done]
        wait = np.where(np.isnan(pick), H, pick) - spawn
        busy = 0.0
        for r, a, dl in zip(pk, assigned, deliv, strict=True):
            if np.isnan(a):
                continue
            end = H if np.isnan(dl) else dl
            busy += max(0.0, min(end, H) - max(a, w))
            assert r["drone"] != ""
        kinds = [e["kind"] for e in self.events]
        flights = [e for e in self.events if e["kind"] == "takeoff"]
        want = {
            "offered": offered,
            "delivered": delivered,
            "delivered_per_hour": delivered / window_h,
            "offered_per_hour": offered / window_h,
            "served_share": delivered / offered if offered else None,
            "p50_delivery_s": float(np.percentile(times, 50)) if len(times) else None,
            "p95_delivery_s": float(np.percentile(times, 95)) if len(times) else None,
            "max_wait_s": float(wait.max()) if len(wait) else 0.0,  # nobody waited
            "loiters": kinds.count("landing_denied"),
            "loiter_s": kinds.count("landing_denied") * 2 * math.pi * s.drone.turn_radius
            / s.drone.cruise_speed,
            "flights": len(flights),
            "reposition_flights": sum(1 for e in flights if "package" not in e),
            "lost": self.numbers.get("lost", 0),
            "mean_cycle_s": busy / delivered if delivered else None,
            "busy_share": busy / (s.drones * (H - w)),
            "capacity_bound_per_hour": s.drones * 3600.0 * delivered / busy
            if delivered and busy > 0 else None,
        }
        self.numbers.update(want)
        for k, v in want.items():
            got = rep.get(k)
            if v is None or got is None:
                if (v is None) != (got is None):
                    self.bad(f"report.json {k}: {got}, the files give {v}")
                continue
            # times are written to the millisecond: sums of a few of them differ by that
            tol = {"p50_delivery_s": 2 * MS, "p95_delivery_s": 2 * MS, "max_wait_s": 2 * MS,
                   "mean_cycle_s": 2 * MS, "busy_share": 1e-6,
                   "capacity_bound_per_hour": 1e-3}.get(k, 1e-9)
            if abs(got - v) > tol * max(1.0, abs(v)) if k in ("busy_share",
                                                             "capacity_bound_per_hour") \
                    else abs(got - v) > tol:
                self.bad(f"report.json {k}: {got}, the files give {v}")
        if rep["delivered_per_hour"] > (rep["capacity_bound_per_hour"] or math.inf) + 1e-9:
            self.bad("report.json: delivered_per_hour over capacity_bound_per_hour")
        geo_flights = [f for f in self.run["geojson"]["features"]
                       if f["properties"].get("kind") in ("delivery", "reposition")]
        if len(geo_flights) != len(flights):
            self.bad(f"fleet.geojson: {len(geo_flights)} flight tracks, {len(flights)} "
                     "takeoff events")


def _segment_minima(r0: np.ndarray, r1: np.ndarray, sh, sv):
    """For relative positions moving in a straight line from ``r0`` to ``r1`` (rows):
    the least horizontal distance while closer than ``sv`` vertically, and the least
    vertical distance while closer than ``sh`` horizontally (NaN where never);
    ``sh`` and ``sv`` are numbers or one per row."""
    a, b = r0[:, :2], r1[:, :2] - r0[:, :2]
    z0, dz = r0[:, 2], r1[:, 2] - r0[:, 2]
    eps = 1e-6  # "closer than": exactly sv apart is not closer
    sh, sv = np.broadcast_to(sh, z0.shape), np.broadcast_to(sv, z0.shape)
    # s in [lo, hi] where |z0 + s dz| < sv
    with np.errstate(divide="ignore", invalid="ignore"):
        s1 = (-(sv - eps) - z0) / dz
        s2 = ((sv - eps) - z0) / dz
    flat = dz == 0
    with np.errstate(invalid="ignore"):
        lo = np.where(flat, np.where(np.abs(z0) < sv - eps, 0.0, np.inf), np.minimum(s1, s2))
        hi = np.where(flat, np.where(np.abs(z0) < sv - eps, 1.0, -np.inf), np.maximum(s1, s2))
    lo, hi = np.maximum(lo, 0.0), np.minimum(hi, 1.0)
    bb = (b * b).sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s_star = np.where(bb > 0, -(a * b).sum(axis=1) / bb, 0.0)
    s = np.clip(s_star, lo, np.maximum(lo, hi))
    with np.errstate(invalid="ignore"):
        h = np.hypot(*(a + s[:, None] * b).T)
    h = np.where(lo <= hi, h, np.nan)
    # s where |a + s b| < sh: roots of bb s^2 + 2 a.b s + |a|^2 - sh^2
    ab, aa = (a * b).sum(axis=1), (a * a).sum(axis=1)
    disc = ab * ab - bb * (aa - sh * sh)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(np.maximum(disc, 0.0))
        l2 = np.where(bb > 0, (-ab - root) / bb, np.where(aa < sh * sh, 0.0, np.inf))
        h2 = np.where(bb > 0, (-ab + root) / bb, np.where(aa < sh * sh, 1.0, -np.inf))
    l2 = np.where((bb > 0) & (disc <= 0), np.inf, l2)
    l2, h2 = np.maximum(l2, 0.0), np.minimum(h2, 1.0)
    with np.errstate(invalid="ignore"):
        za, zb = z0 + l2 * dz, z0 + h2 * dz
        v = np.where(za * zb <= 0, 0.0, np.minimum(np.abs(za), np.abs(zb)))
    v = np.where(l2 <= h2, v, np.nan)
    return h, v


def audit(folder, scenario, **kw) -> tuple[list[str], dict]:
    """(problems, recomputed numbers) of the run written in ``folder``; the numbers'
    ``notes`` are :meth:`Audit.note`'s."""
    a = Audit(folder, scenario, **kw)
    problems = a.check()
    a.numbers["notes"] = a.notes
    return problems, a.numbers
