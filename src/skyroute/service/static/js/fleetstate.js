// A fleet run as the replay needs it: the tracks (tracks.csv: t,drone,north,east,alt,phase,
// sorted by time then drone; a drone at its gate has no rows) in typed arrays, and the
// state of every drone and package at a time t, folded from the events (events.jsonl).

import { ShapeError } from "./shape.js";

export const PARKED = "at gate";

/**
 * When a run ends, in seconds: its report's ``settings.end_s`` (the hours times 3600
 * rounded to the millisecond its files write times to, ``packages.horizon_seconds``);
 * for a run stored before reports gave it, the hours (``params.hours`` or the report's
 * ``simulated_hours``) rounded the same way; 0 when neither is known.
 */
export function runEnd(report, params) {
  const end = Number(((report || {}).settings || {}).end_s);
  if (Number.isFinite(end) && end > 0) return end;
  const hours = Number((params || {}).hours ?? (report || {}).simulated_hours);
  return Number.isFinite(hours) && hours > 0 ? Math.round(hours * 3600 * 1000) / 1000 : 0;
}

/** tracks.csv -> columns; ``byDrone`` maps a drone to its row numbers (in time order). */
export function parseTracks(text) {
  const lines = text.split("\n");
  const header = (lines[0] || "").trim().split(",");
  const col = Object.fromEntries(header.map((name, i) => [name, i]));
  for (const name of ["t", "drone", "north", "east", "alt", "phase"]) {
    if (!(name in col)) throw new ShapeError(`tracks.csv has no column ${name}`);
  }
  let n = 0;
  for (let i = 1; i < lines.length; i++) if (lines[i]) n++;
  const t = new Float64Array(n);
  const drone = new Int32Array(n);
  const north = new Float32Array(n);
  const east = new Float32Array(n);
  const alt = new Float32Array(n);
  const phase = new Uint8Array(n);
  const phases = [];
  const code = new Map();
  let k = 0;
  for (let i = 1; i < lines.length; i++) {
    const line = lines[i];
    if (!line) continue;
    const f = line.split(",");
    if (f.length < header.length) {
      throw new ShapeError(`tracks.csv line ${i + 1} has ${f.length} fields, not ${header.length}`);
    }
    t[k] = +f[col.t];
    drone[k] = +f[col.drone];
    north[k] = +f[col.north];
    east[k] = +f[col.east];
    alt[k] = +f[col.alt];
    const name = f[col.phase].trim();
    if (!code.has(name)) {
      code.set(name, phases.length);
      phases.push(name);
    }
    phase[k] = code.get(name);
    k++;
  }
  const lists = new Map();
  for (let i = 0; i < n; i++) {
    if (!lists.has(drone[i])) lists.set(drone[i], []);
    lists.get(drone[i]).push(i);
  }
  const byDrone = new Map([...lists].map(([d, rows]) => [d, Int32Array.from(rows)]));
  let step = Infinity;
  for (const rows of byDrone.values()) {
    for (let i = 1; i < rows.length; i++) {
      const dt = t[rows[i]] - t[rows[i - 1]];
      if (dt > 0 && dt < step) step = dt;
    }
  }
  return { n, t, drone, north, east, alt, phase, phases, byDrone, step: Number.isFinite(step) ? step : 1 };
}

/** events.jsonl -> events (already in time order); a line that is no JSON object is an
 * Error naming it. */
export function parseEvents(text) {
  const events = [];
  text.split("\n").forEach((line, i) => {
    if (!line.trim()) return;
    let e;
    try {
      e = JSON.parse(line);
    } catch {
      e = null;
    }
    if (!e || typeof e !== "object" || typeof e.t !== "number") {
      throw new ShapeError(`events.jsonl line ${i + 1} is not an event (a JSON object with a time t)`);
    }
    events.push(e);
  });
  return events;
}

/** packages.csv -> Map id -> {from, to}. */
export function parseRoutes(text) {
  const lines = text.split("\n").filter((line) => line.trim());
  if (!lines.length) throw new ShapeError("packages.csv is empty (it has no header line)");
  const header = lines[0].split(",");
  const at = (name) => header.indexOf(name);
  const [id, from, to] = [at("id"), at("from_airport"), at("to_airport")];
  const out = new Map();
  for (const line of lines.slice(1)) {
    const f = line.split(",");
    out.set(Number(f[id]), { from: f[from], to: f[to] });
  }
  return out;
}

/** The last row of ``rows`` (ascending row numbers of one drone) at or before time t. */
function lastAtOrBefore(tr, rows, t) {
  let lo = 0;
  let hi = rows.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (tr.t[rows[mid]] <= t) lo = mid + 1;
    else hi = mid;
  }
  return lo - 1; // an index into rows, -1 when none
}

/** Every drone's phase, place and altitude at time t: [{id, phase, north, east, alt, flying}]. */
export function dronesAt(tr, t, count) {
  const out = [];
  for (let d = 0; d < count; d++) {
    const rows = tr.byDrone.get(d);
    if (!rows || !rows.length) {
      out.push({ id: d, phase: PARKED, north: null, east: null, alt: 0, flying: false });
      continue;
    }
    const i = lastAtOrBefore(tr, rows, t);
    // before its first flight a drone waits at the gate the flight leaves from
    const r = rows[Math.max(i, 0)];
    const current = i >= 0 && t - tr.t[r] < tr.step * 1.001 && (i + 1 < rows.length
      ? tr.t[rows[i + 1]] - tr.t[r] < tr.step * 1.001 : t - tr.t[r] < 1e-9);
    out.push({
      id: d, phase: current ? tr.phases[tr.phase[r]] : PARKED, north: tr.north[r], east: tr.east[r],
      alt: current ? tr.alt[r] : 0, flying: current, row: r, index: i,
    });
  }
  return out;
}

/** The rows of drone ``d`` from ``since`` to ``t`` (its recent trail), as [east, north] points. */
export function trail(tr, d, since, t) {
  const rows = tr.byDrone.get(d);
  if (!rows) return [];
  const last = lastAtOrBefore(tr, rows, t);
  const pts = [];
  for (let i = last; i >= 0; i--) {
    const r = rows[i];
    if (tr.t[r] < since) break;
    if (i < last && tr.t[rows[i + 1]] - tr.t[r] > tr.step * 1.001) break; // a gap: a parked spell
    pts.push([tr.east[r], tr.north[r]]);
  }
  return pts.reverse();
}

/** Folds events into the packages' and drones' jobs at a time; forward steps reuse the
 * previous fold, a step back starts again. */
export class EventFold {
  constructor(events, routes = null) {
    this.events = events;
    this.routes = routes;
    this.reset();
  }

  reset() {
    this.i = 0;
    this.t = -Infinity;
    this.packages = new Map(); // id -> {id, from, to, state, drone, since}
    this.job = new Map(); // drone -> package id
  }

  at(t) {
    if (t < this.t) this.reset();
    const ev = this.events;
    while (this.i < ev.length && ev[this.i].t <= t) this.apply(ev[this.i++]);
    this.t = t;
    return this;
  }

  apply(e) {
    const p = e.package;
    const pk = p === undefined ? null : this.packages.get(p);
    switch (e.kind) {
      case "spawn": {
        const route = this.routes ? this.routes.get(p) : null;
        this.packages.set(p, { id: p, from: e.airport, to: route ? route.to : null, state: "waiting", drone: null, since: e.t });
        break;
      }
      case "assign":
        if (pk) Object.assign(pk, { state: "assigned", drone: e.drone, since: e.t });
        this.job.set(e.drone, p);
        break;
      case "pickup":
        if (pk) Object.assign(pk, { state: "carried", since: e.t });
        this.job.set(e.drone, p);
        break;
      case "landing_request":
      case "landing_granted":
        if (pk && pk.to === null && e.airport) pk.to = e.airport;
        break;
      case "delivered":
        if (pk) Object.assign(pk, { state: "delivered", to: e.airport || pk.to, since: e.t });
        if (this.job.get(e.drone) === p) this.job.delete(e.drone);
        break;
      default:
        break;
    }
  }
}
