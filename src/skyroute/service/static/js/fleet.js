// Fleet replay: a stored fleet run (or a new one, started as a job) replayed on a
// minimap of airports, runways and gates, with a drone table and a package table that
// follow the time slider, as the seed's testbed GUI and minimap did.
//
// Reads GET /fleet/runs (a page of 100 runs at a time: "List older runs" follows its Link
// to the next), /fleet/runs/{id}, its tracks.csv, events.jsonl, fleet.geojson and
// packages.csv; starts runs with POST /jobs/fleet and follows GET /jobs/{id}.

import { ApiError, bindToken, choices, explain, focusFault, getJSON, getPage, getText, mayPass, postJSON } from "./api.js";
import { EventFold, dronesAt, parseEvents, parseRoutes, parseTracks, runEnd, trail } from "./fleetstate.js";
import { JobFollower, jobId } from "./jobs.js";
import { Player } from "./player.js";
import { fitsIn, runLabel, runLabels, runParts } from "./runlabels.js";
import { Answer, readable } from "./shape.js";
import { PALETTE, clock, fmt, h, isBusy, say, setBusy } from "./ui.js";
import { MapView, bbox, dot, grow, label, localProjection } from "./view.js";

const $ = (id) => document.getElementById(id);
const status = $("status");
const jobStatus = $("job-status");
const runSelect = $("run");
const moreRuns = $("more-runs");
const runCount = $("run-count");
const RUNS_PAGE = 100; // runs listed at a time (GET /fleet/runs pages them)
const TRAIL_S = 90; // seconds of track drawn behind a flying drone
const TABLE_EVERY_MS = 150; // table refreshes while playing
const MAX_PACKAGE_ROWS = 60;

let runs = []; // the runs listed, newest first
let nextRuns = null; // the URL of the page of older runs (the Link rel="next"), or null
let outOfPage = null; // a run the page's link names, older than the pages listed: last
let listing = 0; // counts the listings: a page of older runs for an old listing is dropped
let run = null; // {id, tracks, fold, ground, drones, horizon}
let t = 0;
let lastTables = 0;
let loading = 0; // counts the runs asked for: only the last one asked is shown
let missing = null; // a run the page's link (#run=) names that the store does not hold
let noRun = "Nothing to draw yet: reading the stored runs…"; // why no run is shown

const view = new MapView($("map"), { draw: drawMap, empty: emptyWhy });
const player = new Player({
  play: $("play"), speed: $("speed"), slider: $("time"), output: $("time-text"),
  describe: (x) => (run ? `${clock(x)} of ${clock(run.horizon)}` : "0:00"),
  onTime: (x) => {
    t = x;
    view.render();
    const now = performance.now();
    if (!player.playing || now - lastTables > TABLE_EVERY_MS) {
      lastTables = now;
      tables();
    }
  },
  onEnd: () => {
    tables();
    if (run) say(status, `Replay of ${run.name} finished at ${clock(run.horizon)}.`, "ok");
  },
});
bindToken($("token"));

/** Why the map has nothing on it ("" when it has): no run, or one with nothing to place. */
function emptyWhy() {
  if (!run) return noRun;
  const g = run.ground;
  return run.tracks.n || g.airports.length || g.gates.length || g.runways.length || g.zones.length ? ""
    : "Nothing to draw: this run has no airports, no no-fly zones and no tracks.";
}

function colour(d, count) {
  if (count <= PALETTE.length) return PALETTE[d % PALETTE.length];
  return `hsl(${(d * 137.508) % 360}, 65%, 42%)`;
}

/** GET /fleet/runs's page (at ``where``) as the list reads it: runs with their ids. */
function checkRuns(items, where) {
  const a = new Answer(where, "a list of runs");
  return a.list(items, "", (r, f) => {
    a.object(r, f);
    if (typeof r.id !== "number") a.string(r.id, `${f}.id`);
    for (const k of ["params", "report"]) a.maybe(r[k], `${f}.${k}`, a.object);
    for (const k of ["scenario", "created"]) a.maybe(r[k], `${f}.${k}`, a.string);
  });
}

/** A run's GET /fleet/runs/{id} and fleet.geojson (at ``where``) as show() reads them. */
function checkRun(detail, geo, where) {
  const a = new Answer(where, "a fleet run");
  a.object(detail);
  for (const k of ["scenario", "params", "report", "files"]) a.maybe(detail[k], k, a.object);
  new Answer(`${where}/fleet.geojson`, "a fleet's ground (GeoJSON)").features(geo);
}

function showRuns() {
  const keep = runSelect.value;
  runSelect.replaceChildren(...runs.map((r) => h("option", { value: r.id })));
  labelRuns();
  if (runs.some((r) => String(r.id) === keep)) runSelect.value = keep;
  chosenTitle();
  moreRuns.hidden = !nextRuns;
  const n = runs.length;
  runCount.textContent = !n ? "" : nextRuns ? `The newest ${n} runs are listed; older ones follow.`
    : n === 1 ? "" : `All ${n} stored runs are listed, newest first.`;
}

/** Label the listed runs to fit the list's width (runlabels.js): each the longest form
 * of its label that fits, its whole label its tooltip. Labels alike (runs stored in one
 * minute, or in one second, or by a server without their time) say more (the seconds,
 * then the run's id), so that every run in the list can be told apart. */
function labelRuns() {
  const options = [...runSelect.options];
  if (options.length !== runs.length || options.some((o, i) => o.value !== String(runs[i].id))) return;
  const fits = fitsIn(runSelect);
  let labels = runs.map((r) => runLabels(r, fits));
  for (let alike = 1; alike <= 2; alike++) {
    const shorts = labels.map((l) => l.short);
    const twice = new Set(shorts.filter((x, i) => shorts.indexOf(x) !== i));
    if (!twice.size) break;
    labels = labels.map((l, i) => (twice.has(l.short) ? runLabels(runs[i], fits, alike) : l));
  }
  options.forEach((o, i) => {
    o.textContent = labels[i].short;
    o.title = labels[i].whole;
  });
}

/** The list's tooltip: the whole label of the run chosen. */
function chosenTitle() {
  runSelect.title = runSelect.selectedOptions[0] ? runSelect.selectedOptions[0].title : "";
}

let listWidth = 0;
new ResizeObserver(() => {
  if (runSelect.clientWidth === listWidth) return;
  listWidth = runSelect.clientWidth;
  labelRuns();
}).observe(runSelect);

/** List the runs (``select`` chosen when listed) and show one; a failure says so with a
 * way to ask again. */
async function showRunList(select = null) {
  if (await listRuns(select)) await load(runSelect.value);
}

async function listRuns(select = null) {
  const mine = ++listing;
  let page;
  try {
    page = await getPage(`/fleet/runs?limit=${RUNS_PAGE}`);
    checkRuns(page.items, "/fleet/runs");
  } catch (err) {
    if (mine !== listing) return false;
    runSelect.replaceChildren(h("option", {}, "no runs"));
    moreRuns.hidden = true;
    if (!run) noRun = "Nothing to draw: the stored runs could not be read.";
    view.render();
    // the server's own words: a 503 is an installation without fleet runs (for good) or
    // a store busy or out of reach (for now; it says which)
    const gone = err instanceof ApiError && err.status === 503 && /not available/.test(err.detail);
    say(status, explain(err, "Reading the fleet runs"), "error",
      { retry: mayPass(err) && !gone ? () => showRunList(select) : null });
    return false;
  }
  runs = page.items;
  nextRuns = page.next;
  outOfPage = null;
  if (!runs.length) {
    showRuns(); // (an empty list) before the line that says so, which it replaced
    runSelect.replaceChildren(h("option", {}, "no stored runs"));
    runSelect.disabled = true;
    noRun = "Nothing to draw: no fleet run is stored yet.";
    view.render();
    say(status, "No fleet run is stored yet: start one below.", "info");
    return false;
  }
  const linked = select ? null : new URLSearchParams(location.hash.slice(1)).get("run");
  const wanted = select || linked;
  if (wanted && nextRuns && !runs.some((r) => String(r.id) === wanted)) {
    // a run older than the first page (a link to run 101): listed last until its page is
    try {
      const where = `/fleet/runs/${encodeURIComponent(wanted)}`;
      const d = await getJSON(`${where}?limit=1`);
      if (mine !== listing) return false;
      checkRun(d, { features: [] }, where);
      runs.push({ id: String(d.id), scenario: (d.scenario || {}).name, params: d.params, report: d.report });
      outOfPage = String(d.id);
    } catch {
      // not stored (404) or unreadable: the newest is shown, and the note says so
    }
  }
  showRuns();
  runSelect.disabled = false;
  if (wanted && runs.some((r) => String(r.id) === wanted)) runSelect.value = wanted;
  else if (linked) missing = linked;
  return true;
}

async function listOlderRuns() {
  if (isBusy(moreRuns) || !nextRuns) return;
  const mine = listing;
  setBusy(moreRuns, true);
  runCount.textContent = "Reading older runs…";
  let page;
  try {
    page = await getPage(nextRuns);
    checkRuns(page.items, "/fleet/runs");
  } catch (err) {
    setBusy(moreRuns, false);
    showRuns();
    say(status, explain(err, "Reading older runs"), "error");
    return;
  }
  setBusy(moreRuns, false);
  if (mine !== listing) return; // the runs were listed anew meanwhile (a new run stored)
  if (outOfPage && page.items.some((r) => String(r.id) === outOfPage)) {
    runs = runs.filter((r) => String(r.id) !== outOfPage); // now in its place
    outOfPage = null;
  }
  // a run stored since the first page moves the others down: one may come twice
  const known = new Set(runs.map((r) => String(r.id)));
  runs.push(...page.items.filter((r) => !known.has(String(r.id))));
  nextRuns = page.next;
  showRuns();
  if (!nextRuns) runSelect.focus(); // the button is gone: the focus goes to the longer list
}

async function load(id) {
  player.pause();
  const mine = ++loading;
  const entry = runs.find((r) => String(r.id) === String(id)) || { id };
  const base = `/fleet/runs/${encodeURIComponent(id)}`;
  say(status, `Loading run ${runLabel(entry, { when: false })}…`, "busy");
  let detail, tracksText, eventsText, geo, routesText;
  try {
    const asked = getJSON(`${base}?limit=1`);
    [detail, tracksText, eventsText, geo, routesText] = await Promise.all([
      asked, getText(`${base}/tracks.csv`), getText(`${base}/events.jsonl`),
      getJSON(`${base}/fleet.geojson`),
      // routes known from the start (else from events); asked for only where the run's
      // files name it: a run stored without it is a 404, a console error in the browser
      asked.then((d) => (((d && d.files) || {})["packages.csv"] ? getText(`${base}/packages.csv`) : null))
        .catch(() => null),
    ]);
    checkRun(detail, geo, base);
  } catch (err) {
    if (mine !== loading) return;
    say(status, explain(err, "Reading the run"), "error", { retry: mayPass(err) ? () => load(id) : null });
    if (!run) noRun = "Nothing to draw: the run could not be read.";
    view.render();
    // a run deleted since the list was read goes from it; the list shows the run shown
    // again (left on the failed one, choosing that one again asked nothing)
    if (err instanceof ApiError && err.status === 404) {
      runs = runs.filter((r) => String(r.id) !== String(id));
      showRuns();
    }
    if (run) runSelect.value = run.id;
    return;
  }
  if (mine !== loading) return; // another run was chosen while this one was read
  try {
    show(id, entry, detail, tracksText, eventsText, geo, routesText);
  } catch (err) {
    // a file of another shape (cut short, another server's): said, not a page left on
    // "Loading run…" with an exception in the console
    say(status, explain(readable(err, base, "a fleet run"), "Reading the run"), "error");
  }
}

/** Show run ``id`` from its files' texts and answers. */
function show(id, entry, detail, tracksText, eventsText, geo, routesText) {
  const scenario = [detail.scenario, (detail.params || {}).scenario, (entry.params || {}).scenario]
    .find((s) => s && typeof s === "object" && s.home_lon !== undefined);
  if (!scenario) {
    say(status, "This run does not give its scenario's home (home_lon, home_lat): its tracks cannot be placed.", "error");
    return;
  }
  const tracks = parseTracks(tracksText);
  const events = parseEvents(eventsText);
  const proj = localProjection(scenario.home_lon, scenario.home_lat);
  const ground = { airports: [], gates: [], runways: [], zones: [] };
  for (const f of geo.features || []) {
    const p = f.properties || {};
    const g = f.geometry;
    if (!g) continue;
    const point = g.type === "Point";
    if (p.kind === "airport" && point) ground.airports.push({ id: String(p.id), at: proj.fwd(g.coordinates) });
    else if (p.kind === "gate" && point) ground.gates.push({ airport: p.airport, gate: p.gate, at: proj.fwd(g.coordinates) });
    else if ((p.kind === "landing" || p.kind === "takeoff") && g.type === "LineString") {
      ground.runways.push({ kind: p.kind, airport: p.airport, line: g.coordinates.map((c) => proj.fwd(c)) });
    } else if (p.kind === "no_fly_zone" && g.type === "Polygon") {
      ground.zones.push({ name: String(p.name || ""), ring: g.coordinates[0].map((c) => proj.fwd(c)) });
    }
  }
  const rep = detail.report || entry.report || {};
  const params = detail.params || entry.params || {};
  let maxDrone = -1;
  for (const d of tracks.byDrone.keys()) maxDrone = Math.max(maxDrone, d);
  const drones = Math.max(maxDrone + 1, Number((rep.settings || {}).drones) || 0);
  const lastEvent = events.length ? events[events.length - 1].t : 0;
  const horizon = runEnd(rep, params) || Math.max(tracks.n ? tracks.t[tracks.n - 1] : 0, lastEvent);
  const pts = [...ground.airports.map((a) => a.at), ...ground.gates.map((g) => g.at), ...ground.runways.flatMap((r) => r.line),
    ...ground.zones.flatMap((z) => z.ring)];
  let b = bbox(pts);
  for (let i = 0; i < tracks.n; i++) b = bbox([[tracks.east[i], tracks.north[i]]], b);
  if (!Number.isFinite(b[0])) b = [0, 0, 1000, 600]; // nothing to place: the map says so
  run = {
    id, name: runLabel(entry, { when: false }), tracks, drones, horizon, ground,
    fold: new EventFold(events, routesText ? parseRoutes(routesText) : null),
  };
  history.replaceState(null, "", `#run=${encodeURIComponent(id)}`);
  if (runs.some((r) => String(r.id) === String(id))) runSelect.value = id; // (asked again)
  chosenTitle();
  const parts = runParts({ ...entry, params, report: rep });
  $("s-stored").textContent = parts.at ? parts.at.whole : "–";
  $("s-hours").textContent = [parts.hours, parts.seed].filter(Boolean).join(", ") || "–";
  $("s-scenario").textContent = `${scenario.name || entry.scenario || "–"}, ${params.scheduler || (rep.settings || {}).scheduler || "seed"} dispatch`;
  $("s-size").textContent = `${ground.airports.length} airports, ${drones} drones`;
  $("s-delivered").textContent = rep.delivered === undefined ? "–" : `${rep.delivered} of ${rep.offered} packages`;
  $("s-rate").textContent = rep.delivered_per_hour === undefined ? "–" : `${fmt(rep.delivered_per_hour, 1)} delivered`;
  $("s-safety").textContent = rep.loiters === undefined ? "–" : `${rep.loiters}, ${rep.conflicts}`;
  view.setBounds(grow(b, 0.04, 50));
  player.load(horizon, tracks.step);
  const note = missing ? `The link names run ${missing}, which is not stored; this is the newest. ` : "";
  missing = null;
  say(status, `${note}${run.name}: ${clock(horizon)} of flying, ${events.length} events. Press Play or move the time slider.`,
    note ? "info" : "ok");
}

function tables() {
  if (!run) return;
  const fold = run.fold.at(t);
  const drones = dronesAt(run.tracks, t, run.drones);
  $("drones").querySelector("tbody").replaceChildren(...drones.map((d) => {
    const p = fold.job.get(d.id);
    const pk = p === undefined ? null : fold.packages.get(p);
    const what = pk ? `#${p} ${pk.state === "carried" ? "carried" : "to fetch"}` : "–";
    return h("tr", { dataset: { drone: d.id, phase: d.phase } },
      h("td", { class: "num" }, h("span", { class: "swatch", style: `background:${colour(d.id, run.drones)}`, "aria-hidden": "true" }), d.id),
      h("td", {}, d.phase), h("td", { class: "num" }, fmt(d.alt, 1)), h("td", {}, what),
      h("td", { class: "num" }, d.north === null ? "–" : `${fmt(d.north, 0)}, ${fmt(d.east, 0)}`));
  }));
  const all = [...fold.packages.values()];
  const count = { waiting: 0, assigned: 0, carried: 0, delivered: 0 };
  for (const p of all) count[p.state] += 1;
  const open = all.filter((p) => p.state !== "delivered").sort((a, b) => a.id - b.id);
  const done = all.filter((p) => p.state === "delivered").sort((a, b) => b.since - a.since);
  const shown = [...open, ...done].slice(0, MAX_PACKAGE_ROWS);
  $("packages-caption").textContent = `Packages at ${clock(t)}: ${count.waiting} waiting, ${count.assigned} assigned, ` +
    `${count.carried} carried, ${count.delivered} delivered` + (all.length > shown.length ? ` (first ${shown.length} shown)` : "");
  const tag = { waiting: "tag busy", assigned: "tag", carried: "tag", delivered: "tag ok" };
  $("packages").querySelector("tbody").replaceChildren(...shown.map((p) => h("tr", { dataset: { package: p.id, state: p.state } },
    h("td", { class: "num" }, p.id), h("td", {}, p.from ?? "?"), h("td", {}, p.to ?? "?"),
    h("td", {}, h("span", { class: tag[p.state] }, p.state)), h("td", { class: "num" }, p.drone ?? "–"))));
}

function drawMap(ctx, v) {
  if (!run) return;
  const g = run.ground;
  for (const z of g.zones) { // under everything: the tracks go round them
    v.path(z.ring, true);
    ctx.fillStyle = "rgba(179, 38, 30, 0.12)";
    ctx.fill();
    ctx.strokeStyle = "#b3261e";
    ctx.lineWidth = 1.5;
    ctx.stroke();
    const c = z.ring.slice(0, -1).reduce((s, q) => [s[0] + q[0], s[1] + q[1]], [0, 0]);
    const n = Math.max(z.ring.length - 1, 1);
    label(ctx, z.name, v.px([c[0] / n, c[1] / n]), { align: "center", font: "italic 11px system-ui, sans-serif", color: "#8c1d18" });
  }
  ctx.lineCap = "butt";
  for (const kind of ["takeoff", "landing"]) {
    for (const r of g.runways.filter((x) => x.kind === kind)) {
      v.path(r.line);
      ctx.strokeStyle = kind === "landing" ? "#3b4252" : "#aab2c0";
      ctx.lineWidth = 5;
      ctx.stroke();
    }
  }
  for (const gate of g.gates) {
    const [x, y] = v.px(gate.at);
    ctx.fillStyle = "#b3261e";
    ctx.fillRect(x - 3, y - 3, 6, 6);
  }
  for (const a of g.airports) {
    const [x, y] = v.px(a.at);
    label(ctx, a.id, [x + 9, y - 9], { font: "bold 13px system-ui, sans-serif" });
  }
  const drones = dronesAt(run.tracks, t, run.drones);
  ctx.lineCap = "round";
  ctx.lineJoin = "round";
  for (const d of drones) {
    if (!d.flying) continue;
    const pts = trail(run.tracks, d.id, t - TRAIL_S, t);
    if (pts.length < 2) continue;
    v.path(pts);
    ctx.strokeStyle = colour(d.id, run.drones);
    ctx.globalAlpha = 0.55;
    ctx.lineWidth = 2;
    ctx.stroke();
    ctx.globalAlpha = 1;
  }
  const small = v.width < 500;
  for (const d of drones) {
    if (d.north === null) continue;
    const at = v.px([d.east, d.north]);
    const c = colour(d.id, run.drones);
    if (d.flying) {
      dot(ctx, at, small ? 5 : 6.5, c);
      if (run.drones <= 30) label(ctx, String(d.id), [at[0] + 8, at[1] + 4], { font: "11px system-ui, sans-serif" });
    } else {
      ctx.beginPath();
      ctx.arc(at[0], at[1], 4, 0, 2 * Math.PI);
      ctx.strokeStyle = c;
      ctx.lineWidth = 2;
      ctx.stroke();
    }
  }
}

// -- new runs as jobs --------------------------------------------------------------
const jobs = new JobFollower({
  key: "skyroute.fleetJob", bar: $("progress"), line: jobStatus, button: $("start"),
  what: "the run", done: "The run is done and stored.",
  onDone: async (r) => {
    const runId = r.fleet_run ?? r.run_id ?? r.id;
    if (runId !== undefined) await showRunList(String(runId));
  },
});

$("job").addEventListener("submit", async (ev) => {
  ev.preventDefault();
  if (isBusy($("start"))) return; // a run is under way (Enter in a field submits too)
  const body = {
    preset: $("preset").value, scheduler: $("scheduler").value,
    hours: Number($("hours").value), seed: Number($("seed").value),
  };
  setBusy($("start"), true);
  $("progress").value = 0;
  say(jobStatus, "Submitting the run…", "busy");
  let id;
  try {
    id = jobId(await postJSON("/jobs/fleet", body), "/jobs/fleet");
  } catch (err) {
    say(jobStatus, explain(err, "Starting the run"), "error");
    focusFault(err, { hours: "hours", seed: "seed", preset: "preset", scheduler: "scheduler" });
    setBusy($("start"), false);
    return;
  }
  await jobs.start(id);
});

async function start() {
  const [presets, schedulers] = await Promise.all([
    choices("FleetJob", "preset", ["seed-3x3", "seed-9x9", "seed-18x9"]),
    choices("FleetJob", "scheduler", ["seed", "optimal"]),
  ]);
  $("preset").replaceChildren(...presets.map((p) => h("option", { value: p }, p)));
  $("scheduler").replaceChildren(...schedulers.map((s) => h("option", { value: s }, s)));
  runSelect.addEventListener("change", () => load(runSelect.value));
  moreRuns.addEventListener("click", listOlderRuns);
  view.setBounds([0, 0, 1000, 600]);
  const job = jobs.remembered(); // a run started before a reload: followed after the list
  if (job) {
    setBusy($("start"), true);
    say(jobStatus, "Following the run started before this page was loaded…", "busy");
  }
  await showRunList();
  if (job) await jobs.follow(job);
}

start().catch((err) => say(status, explain(err, "Loading the page"), "error"));
