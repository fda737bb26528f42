// World planning: a colliders city or GeoJSON zones (uploaded or pasted) drawn as seen
// from above, a click for the start and one for the goal, the path from POST /plan and
// its waypoints to download.
//
// A colliders world is planned in the "ned" frame (points are north, east metres from the
// file's lat0, lon0); GeoJSON zones in "lonlat" (points are lon, lat).

import { PLAN_WAIT_MS, bindToken, choices, explain, focusFault, postJSON } from "./api.js";
import { checkPlan } from "./shape.js";
import { download, fmt, h, isBusy, say, setBusy } from "./ui.js";
import { MapView, bbox, grow, localProjection } from "./view.js";

const $ = (id) => document.getElementById(id);
const status = $("status");
const GRID_FALLBACK = ["visibility", "prm", "astar", "dijkstra", "bfs", "jps", "theta", "lazy_theta"];

let world = null; // {format, frame, text, name, shapes: [{ring (plane), floor, ceiling}], boundary, proj}
let answer = null;
let round = 0;

let noWorld = "Nothing to draw yet: choose or paste a world file."; // why no world is drawn

const view = new MapView($("map"), { draw: drawMap, empty: () => (world ? "" : noWorld) });
bindToken($("token"));

// -- reading a world file in the page (for drawing and for checking clicks) ----------
function parseColliders(text) {
  const lines = text.split(/\r?\n/);
  const m = /lat0\s+(-?[\d.eE+-]+)\s*,\s*lon0\s+(-?[\d.eE+-]+)/.exec(lines[0] || "");
  if (!m) throw new Error("line 1: expected 'lat0 <deg>, lon0 <deg>'");
  const shapes = [];
  lines.slice(2).forEach((line, i) => {
    if (!line.trim()) return;
    const v = line.split(",").map(Number);
    if (v.length !== 6 || v.some((x) => !Number.isFinite(x))) throw new Error(`line ${i + 3}: expected 6 numbers`);
    const [n, e, up, hn, he, hu] = v;
    shapes.push({ box: [e - he, n - hn, e + he, n + hn], floor: up - hu, ceiling: up + hu });
  });
  if (!shapes.length) throw new Error("no boxes after the header");
  return { format: "colliders", frame: "ned", shapes, boundary: null, proj: null };
}

function parseGeojson(text) {
  const doc = JSON.parse(text);
  if (!doc || doc.type !== "FeatureCollection" || !Array.isArray(doc.features)) {
    throw new Error("expected a GeoJSON FeatureCollection");
  }
  const polys = [];
  let boundary = null;
  for (const f of doc.features) {
    const g = f.geometry || {};
    const p = f.properties || {};
    const list = g.type === "Polygon" ? [g.coordinates] : g.type === "MultiPolygon" ? g.coordinates : [];
    const isBoundary = p.boundary === true || String(p.name || "").toLowerCase().includes("confinement");
    if (isBoundary && list.length) boundary = list[0][0];
    else polys.push(...list);
  }
  if (!polys.length && !boundary) throw new Error("no zones and no boundary");
  const all = [...polys.flatMap((p) => p[0]), ...(boundary || [])];
  const b = bbox(all);
  const proj = localProjection((b[0] + b[2]) / 2, (b[1] + b[3]) / 2);
  const shapes = polys.map((p) => ({ rings: p.map((r) => r.map(proj.fwd)), floor: -Infinity, ceiling: Infinity }));
  return { format: "geojson", frame: "lonlat", shapes, boundary: boundary && boundary.map(proj.fwd), proj };
}

function detect(text) {
  const chosen = $("format").value;
  if (chosen !== "auto") return chosen;
  return text.trimStart().startsWith("{") ? "geojson" : "colliders";
}

function loadText(text, name) {
  round++; // a plan on the old world still under way: its answer is dropped
  setBusy($("run"), false);
  answer = null;
  clearResult();
  if (!text.trim()) {
    world = null;
    noWorld = "Nothing to draw yet: choose or paste a world file.";
    view.render();
    return;
  }
  const format = detect(text);
  try {
    world = format === "geojson" ? parseGeojson(text) : parseColliders(text);
  } catch (err) {
    world = null;
    noWorld = `Nothing to draw: ${name} could not be read as a world (the line below says why).`;
    say(status, `${name}: ${err.message} (as ${format === "geojson" ? "GeoJSON" : "a colliders CSV"}).`, "error");
    view.render();
    return;
  }
  world.text = text;
  world.name = name;
  const ne = world.frame === "ned";
  const labels = ne ? ["north (m)", "east (m)"] : ["lon", "lat"];
  for (const p of ["s", "g"]) {
    for (const k of [0, 1]) {
      $(`l-${p}${k}`).textContent = `${p === "s" ? "Start" : "Goal"} ${labels[k]}`;
      $(`${p}${k}`).value = "";
    }
  }
  const corners = [];
  for (const s of world.shapes) {
    if (s.box) corners.push([s.box[0], s.box[1]], [s.box[2], s.box[3]]);
    else corners.push(...s.rings[0]);
  }
  if (world.boundary) corners.push(...world.boundary);
  view.setBounds(grow(bbox(corners), 0.04, 10));
  say(status, `${name}: ${world.shapes.length} obstacles (${format === "geojson" ? "GeoJSON zones, points in lon/lat"
    : "colliders, points in metres north and east of home"}). Click the start, then the goal.`, "ok");
}

// -- drawing ----------------------------------------------------------------------
function counts(s) {
  const a = Number($("altitude").value);
  return $("altitude").value === "" || (s.floor - safety() <= a && a < s.ceiling + safety());
}

function safety() {
  return Math.max(Number($("safety").value) || 0, 0);
}

function shapePath(ctx, v, s, grown = 0) {
  ctx.beginPath();
  if (s.box) {
    const [x0, y0] = v.px([s.box[0] - grown, s.box[3] + grown]);
    const [x1, y1] = v.px([s.box[2] + grown, s.box[1] - grown]);
    ctx.rect(x0, y0, x1 - x0, y1 - y0);
    return;
  }
  for (const ring of s.rings) {
    ring.forEach((p, i) => {
      const [x, y] = v.px(p);
      if (i) ctx.lineTo(x, y);
      else ctx.moveTo(x, y);
    });
    ctx.closePath();
  }
}

/** A world point (in the frame) <-> the drawing plane (east, north metres). */
function toPlane(p) {
  return world.frame === "ned" ? [p[1], p[0]] : world.proj.fwd(p);
}

function fromPlane([x, y]) {
  return world.frame === "ned" ? [y, x] : world.proj.inv([x, y]);
}

function point(prefix) {
  const a = $(`${prefix}0`).value;
  const b = $(`${prefix}1`).value;
  return a === "" || b === "" ? null : [Number(a), Number(b)];
}

function drawMap(ctx, v) {
  if (!world) return;
  if (world.boundary) {
    v.path(world.boundary, true);
    ctx.setLineDash([6, 4]);
    ctx.strokeStyle = "#5b6475";
    ctx.lineWidth = 1.5;
    ctx.stroke();
    ctx.setLineDash([]);
  }
  const grown = safety();
  const on = world.shapes.filter(counts);
  const off = world.shapes.filter((s) => !counts(s));
  for (const s of off) {
    shapePath(ctx, v, s);
    ctx.fillStyle = "#d8dce4";
    ctx.fill("evenodd");
  }
  if (grown > 0) {
    for (const s of on) {
      shapePath(ctx, v, s, s.box ? grown : 0);
      ctx.fillStyle = "rgba(59, 66, 82, .18)";
      ctx.fill("evenodd");
      if (!s.box) {
        ctx.lineWidth = Math.max(2 * grown * v.scale, 1);
        ctx.strokeStyle = "rgba(59, 66, 82, .18)";
        ctx.stroke();
      }
    }
  }
  for (const s of on) {
    shapePath(ctx, v, s);
    ctx.fillStyle = "#3b4252";
    ctx.fill("evenodd");
  }
  if (answer && answer.path && answer.path.length > 1) {
    v.path(answer.path.map(toPlane));
    ctx.strokeStyle = "#d55e00";
    ctx.lineWidth = 3;
    ctx.lineJoin = "round";
    ctx.stroke();
    for (const p of answer.path) {
      const [x, y] = v.px(toPlane(p));
      ctx.beginPath();
      ctx.arc(x, y, 3, 0, 2 * Math.PI);
      ctx.fillStyle = "#fff";
      ctx.fill();
      ctx.strokeStyle = "#d55e00";
      ctx.lineWidth = 1.5;
      ctx.stroke();
    }
  }
  for (const [p, colour, letter] of [[point("s"), "#1b7a3d", "S"], [point("g"), "#b3261e", "G"]]) {
    if (!p) continue;
    const [x, y] = v.px(toPlane(p));
    ctx.beginPath();
    ctx.arc(x, y, 8, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
    ctx.strokeStyle = "#fff";
    ctx.lineWidth = 2;
    ctx.stroke();
    ctx.fillStyle = "#fff";
    ctx.font = "bold 10px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    ctx.fillText(letter, x, y + 0.5);
    ctx.textAlign = "left";
    ctx.textBaseline = "alphabetic";
  }
}

function inside([x, y], s, grown) {
  if (s.box) return x >= s.box[0] - grown && x <= s.box[2] + grown && y >= s.box[1] - grown && y <= s.box[3] + grown;
  let odd = false;
  for (const ring of s.rings) {
    for (let i = 0, j = ring.length - 1; i < ring.length; j = i++) {
      const [xi, yi] = ring[i];
      const [xj, yj] = ring[j];
      if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) odd = !odd;
    }
  }
  return odd;
}

// -- events -------------------------------------------------------------------------
$("map").addEventListener("click", (ev) => {
  if (!world) return;
  const plane = view.eventPoint(ev);
  if (world.shapes.some((s) => counts(s) && inside(plane, s, s.box ? safety() : 0))) {
    say(status, "That point is inside an obstacle (with its safety margin): pick a free one.", "error");
    return;
  }
  const next = document.querySelector('input[name="next"]:checked').value;
  const prefix = next === "start" ? "s" : "g";
  const p = fromPlane(plane);
  const digits = world.frame === "ned" ? 1 : 6;
  $(`${prefix}0`).value = p[0].toFixed(digits);
  $(`${prefix}1`).value = p[1].toFixed(digits);
  document.querySelector(`input[name="next"][value="${next === "start" ? "goal" : "start"}"]`).checked = true;
  answer = null;
  clearResult();
  view.render();
  if (next === "goal" && point("s")) plan();
  else say(status, "Start set; now click the goal.", "info");
});

// a typed point, altitude or margin is a new query: the path of the old one goes
for (const id of ["s0", "s1", "g0", "g1", "altitude", "safety"]) {
  $(id).addEventListener("input", () => {
    round++;
    setBusy($("run"), false);
    answer = null;
    clearResult();
    view.render();
    if (world) say(status, "Press Plan (or Enter) to plan again.", "info");
  });
}
$("file").addEventListener("change", async () => {
  const f = $("file").files[0];
  if (!f) return;
  const text = await f.text();
  $("text").value = text;
  loadText(text, f.name);
});
$("text").addEventListener("change", () => {
  $("file").value = ""; // the file chosen before is not the world any more
  loadText($("text").value, "the pasted text");
});
$("format").addEventListener("change", () => loadText($("text").value, world ? world.name : "the text"));
$("algorithm").addEventListener("change", () => {
  $("resolution-field").hidden = ["visibility", "prm"].includes($("algorithm").value);
});
$("form").addEventListener("submit", (ev) => {
  ev.preventDefault();
  if (isBusy($("run"))) return; // a plan is under way (Enter in a field submits too)
  plan(); // says what it does (or what is missing) before its first wait
  // on a phone's one column the map and its status line are under the form: bring them up
  status.closest("figure").scrollIntoView({ block: "nearest" });
});

async function plan() {
  if (!world) {
    say(status, "Load a world file first.", "error");
    return;
  }
  const start = point("s");
  const goal = point("g");
  if (!start || !goal) {
    say(status, "Give a start and a goal first (click the map, or type them).", "error");
    return;
  }
  const body = {
    world_text: world.text, world_format: world.format, frame: world.frame, start, goal,
    // the margin as typed: a negative one is the server's to refuse, not the page's to
    // replace by 0 (the drawing does, as it cannot shrink the obstacles)
    algorithm: $("algorithm").value, safety: $("safety").value === "" ? 0 : Number($("safety").value),
  };
  if ($("altitude").value !== "") body.altitude = Number($("altitude").value);
  if (!$("resolution-field").hidden && $("resolution").value !== "") body.resolution = Number($("resolution").value);
  const mine = ++round;
  answer = null; // what is shown is always the answer to the last request
  clearResult();
  view.render();
  setBusy($("run"), true);
  say(status, `Planning with ${body.algorithm}…`, "busy");
  try {
    const a = checkPlan(await postJSON("/plan", body, { wait: PLAN_WAIT_MS }));
    if (mine !== round) return;
    answer = a;
    showResult();
    // typed points may lie outside the world's box: widen the view to them and the path
    const pts = [start, goal, ...(a.path || [])].map(toPlane);
    const [x0, y0, x1, y1] = view.bounds;
    if (pts.some(([x, y]) => x < x0 || x > x1 || y < y0 || y > y1)) view.setBounds(grow(bbox(pts, view.bounds), 0.04, 10));
    say(status, a.status === "found"
      ? `Found a path of ${fmt(a.cost, 1)} m through ${a.path.length} points.`
      : `No path: the planner answered ${a.status.replace("_", " ")}.`, a.status === "found" ? "ok" : "error");
  } catch (err) {
    if (mine !== round) return;
    say(status, explain(err, "Planning"), "error");
    focusFault(err, { safety: "safety", altitude: "altitude", resolution: "resolution", start: "s0",
      goal: "g0", algorithm: "algorithm", world_text: "text" });
  } finally {
    if (mine === round) setBusy($("run"), false);
    view.render();
  }
}

function clearResult() {
  for (const id of ["r-status", "r-cost", "r-expanded", "r-ms", "r-points"]) $(id).textContent = "–";
  $("dl-waypoints").disabled = true;
  $("dl-geojson").disabled = true;
  document.querySelector("#waypoints tbody").replaceChildren();
}

function showResult() {
  const a = answer;
  $("r-status").textContent = a.status.replace("_", " ");
  $("r-cost").textContent = a.cost === null ? "–" : `${fmt(a.cost, 2)} ${world.frame === "degrees" ? "°" : "m"}`;
  $("r-expanded").textContent = fmt(a.expanded);
  $("r-ms").textContent = `${fmt(a.seconds * 1000, 1)} ms`;
  $("r-points").textContent = a.waypoints ? String(a.waypoints.length) : "–";
  $("dl-waypoints").disabled = !a.waypoints;
  $("dl-geojson").disabled = !a.geojson;
  document.querySelector("#waypoints tbody").replaceChildren(...(a.waypoints || []).map((w, i) =>
    h("tr", {}, h("td", { class: "num" }, i), h("td", { class: "num" }, fmt(w[0], 1)),
      h("td", { class: "num" }, fmt(w[1], 1)), h("td", { class: "num" }, fmt(w[2], 1)),
      h("td", { class: "num" }, fmt((((w[3] * 180) / Math.PI) % 360 + 360) % 360, 0)))));
}

function stem() {
  return (world && world.name ? world.name.replace(/\.[^.]*$/, "") : "world").replace(/[^\w.-]+/g, "-");
}

$("dl-waypoints").addEventListener("click", () => {
  if (answer && answer.waypoints) download(`${stem()}-waypoints.json`, `${JSON.stringify(answer.waypoints)}\n`);
});
$("dl-geojson").addEventListener("click", () => {
  if (answer && answer.geojson) download(`${stem()}-path.geojson`, `${JSON.stringify(answer.geojson)}\n`, "application/geo+json");
});

async function start() {
  const all = await choices("PlanRequest", "algorithm", GRID_FALLBACK);
  $("algorithm").replaceChildren(...all.map((a) => h("option", { value: a }, a === "visibility" ? "visibility (exact)" : a)));
  $("algorithm").value = all.includes("visibility") ? "visibility" : all[0];
  view.setBounds([0, 0, 100, 60]);
  say(status, "Choose a world file (or paste one), then click the start and the goal.", "info");
}

start().catch((err) => say(status, explain(err, "Loading the page"), "error"));
