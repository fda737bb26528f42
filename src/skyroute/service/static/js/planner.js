// The planner playground: a bundled map on a canvas, a click for the start and one for
// the goal, and every chosen algorithm's path with its cost, expansions and time.
//
// Reads GET /maps and /maps/{name}; plans with POST /plan (one request per algorithm).

import { PLAN_WAIT_MS, bindToken, choices, explain, focusFault, getJSON, mayPass, postJSON } from "./api.js";
import { Answer, checkPlan } from "./shape.js";
import { PALETTE, fmt, h, isBusy, say, setBusy } from "./ui.js";
import { EmptyNote, KEY, drawScaleBar } from "./view.js";

const $ = (id) => document.getElementById(id);
const status = $("status");
const canvas = $("map");
const ctx = canvas.getContext("2d");
const tbody = document.querySelector("#results tbody");
const mapSelect = $("map-name");
const box = $("algorithms");
const WORLD_ONLY = new Set(["visibility", "prm"]);
const DEFAULT_ON = new Set(["astar", "jps", "theta"]);

let grid = null; // {name, width, height, free: Uint8Array, image: canvas}
let cell = 1; // CSS pixels per cell; the map fills the canvas's top, the key strip its foot
let results = []; // [{algorithm, colour, answer|null, error|null}]
let round = 0; // discards answers of an older query
let loading = 0; // counts the maps asked for: only the last one asked is shown
const note = new EmptyNote(canvas); // why no map is drawn

bindToken($("token"));

/** GET /maps as the list shows it: each map's name and size. */
function checkMaps(maps) {
  const a = new Answer("/maps", "a list of maps");
  return a.list(maps, "", (m, f) => {
    a.object(m, f);
    a.string(m.name, `${f}.name`);
    for (const k of ["width", "height"]) a.number(m[k], `${f}.${k}`);
  });
}

/** GET /maps/{name} (at ``where``) as the canvas draws it: a width and a height of
 * whole cells, a row of text a line, the passable letters. */
function checkMap(doc, where) {
  const a = new Answer(where, "a map");
  a.object(doc);
  for (const k of ["width", "height"]) {
    if (!(Number.isInteger(doc[k]) && doc[k] > 0)) a.fail(k, "a whole number of cells");
  }
  a.list(doc.rows, "rows", a.string);
  a.maybe(doc.passable, "passable", a.string);
  return doc;
}

function terrain(ch, passable) {
  if (passable.includes(ch)) return ch === "S" ? [223, 233, 216] : [255, 255, 255];
  if (ch === "T") return [61, 107, 71];
  if (ch === "W") return [90, 143, 192];
  return [43, 49, 64];
}

async function loadMap(name) {
  const mine = ++loading;
  say(status, `Loading ${name}…`, "busy");
  let doc;
  try {
    const where = `/maps/${encodeURIComponent(name)}`;
    doc = checkMap(await getJSON(where), where);
  } catch (err) {
    if (mine !== loading) return;
    say(status, explain(err, `Reading map ${name}`), "error", { retry: mayPass(err) ? () => loadMap(name) : null });
    if (grid) mapSelect.value = grid.name; // the map shown: choosing the failed one asks again
    else note.show(`Nothing to draw: map ${name} could not be read.`);
    return;
  }
  if (mine !== loading) return; // another map was chosen while this one was read
  round++; // a query on the old map still under way: its answers are dropped
  setBusy($("run"), false);
  mapSelect.value = name; // (asked again after a failure, the list is on the map shown)
  const { width, height, rows } = doc;
  const passable = doc.passable || ".G";
  const free = new Uint8Array(width * height);
  const image = document.createElement("canvas");
  image.width = width;
  image.height = height;
  const ictx = image.getContext("2d");
  const data = ictx.createImageData(width, height);
  for (let y = 0; y < height; y++) {
    const row = rows[y] || "";
    for (let x = 0; x < width; x++) {
      const ch = row[x] || "@";
      free[y * width + x] = passable.includes(ch) ? 1 : 0;
      const [r, g, b] = terrain(ch, passable);
      const i = 4 * (y * width + x);
      data.data.set([r, g, b, 255], i);
    }
  }
  ictx.putImageData(data, 0, 0);
  grid = { name, width, height, free, image };
  note.show("");
  for (const id of ["sx", "gx"]) $(id).max = String(width - 1);
  for (const id of ["sy", "gy"]) $(id).max = String(height - 1);
  for (const id of ["sx", "sy", "gx", "gy"]) $(id).value = "";
  results = [];
  tbody.replaceChildren();
  canvas.setAttribute("aria-label", `Map ${name}, ${width} by ${height} cells: click a free cell ` +
    "for the start, then one for the goal");
  resize();
  say(status, `${name}: ${width} × ${height} cells. Click a free cell for the start, then one for the goal.`, "ok");
}

function resize() {
  if (!grid) {
    note.show(); // (placed over the canvas's new size)
    return;
  }
  const wrap = canvas.parentElement;
  const most = wrap.clientWidth - 18; // the figure's padding
  const tallest = Math.max(240, window.innerHeight * 0.72) - KEY;
  cell = Math.max(Math.min(most / grid.width, tallest / grid.height), 0.25);
  const w = cell * grid.width;
  const hgt = cell * grid.height + KEY; // the scale bar's strip under the map, as MapView's
  const dpr = window.devicePixelRatio || 1;
  canvas.style.width = `${w}px`;
  canvas.style.height = `${hgt}px`;
  canvas.style.margin = "0 auto";
  canvas.width = Math.round(w * dpr);
  canvas.height = Math.round(hgt * dpr);
  draw();
}

let lastWidth = 0;
new ResizeObserver(() => {
  const w = canvas.parentElement.clientWidth;
  if (w !== lastWidth) {
    lastWidth = w;
    resize();
  }
}).observe(canvas.parentElement);

function point(prefix) {
  const x = $(`${prefix}x`).value;
  const y = $(`${prefix}y`).value;
  return x === "" || y === "" ? null : [Number(x), Number(y)];
}

function draw() {
  const dpr = window.devicePixelRatio || 1;
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (!grid) return;
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(grid.image, 0, 0, grid.width * cell, grid.height * cell);
  const centre = ([x, y]) => [(x + 0.5) * cell, (y + 0.5) * cell];
  // the first path widest, so that the ones drawn over it still show it
  results.forEach((r, k) => {
    if (!r.answer || !r.answer.path || r.answer.path.length < 2) return;
    ctx.beginPath();
    r.answer.path.forEach((p, i) => {
      const [x, y] = centre(p);
      if (i) ctx.lineTo(x, y);
      else ctx.moveTo(x, y);
    });
    ctx.strokeStyle = r.colour;
    ctx.globalAlpha = 0.9;
    ctx.lineWidth = Math.max(1.5, 6 - 1.5 * k);
    ctx.lineJoin = "round";
    ctx.lineCap = "round";
    ctx.stroke();
    ctx.globalAlpha = 1;
  });
  for (const [p, colour, letter] of [[point("s"), "#1b7a3d", "S"], [point("g"), "#b3261e", "G"]]) {
    if (!p) continue;
    const [x, y] = centre(p);
    const r = Math.max(6, cell * 0.8);
    ctx.beginPath();
    ctx.arc(x, y, r, 0, 2 * Math.PI);
    ctx.fillStyle = colour;
    ctx.fill();
    ctx.lineWidth = 2;
    ctx.strokeStyle = "#fff";
    ctx.stroke();
    ctx.fillStyle = "#fff";
    ctx.font = `bold ${Math.round(r * 1.2)}px system-ui, sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    ctx.fillText(letter, x, y + 0.5);
  }
  ctx.textBaseline = "alphabetic";
  ctx.textAlign = "left";
  // in the strip under the map, not over its bottom left cells (which it hid); low in
  // it, clear of a start or goal marker on the bottom row (which reaches at most 6 px
  // below the map while cells are at most 20 px)
  drawScaleBar(ctx, cell, "cells", 12, grid.height * cell + KEY - 4);
}

canvas.addEventListener("click", (ev) => {
  if (!grid) return;
  const r = canvas.getBoundingClientRect();
  const px = r.width / grid.width; // CSS pixels per cell as shown; the strip is below them
  const x = Math.floor((ev.clientX - r.left) / px);
  const y = Math.floor((ev.clientY - r.top) / px);
  if (x < 0 || y < 0 || x >= grid.width || y >= grid.height) return; // the key strip too
  if (!grid.free[y * grid.width + x]) {
    say(status, `Cell (${x}, ${y}) is blocked: pick a free (light) cell.`, "error");
    return;
  }
  const next = document.querySelector('input[name="next"]:checked').value;
  const prefix = next === "start" ? "s" : "g";
  $(`${prefix}x`).value = String(x);
  $(`${prefix}y`).value = String(y);
  document.querySelector(`input[name="next"][value="${next === "start" ? "goal" : "start"}"]`).checked = true;
  results = [];
  tbody.replaceChildren();
  draw();
  if (next === "goal" && point("s")) plan();
  else say(status, `Start (${x}, ${y}); now click the goal.`, "info");
});

// a typed cell is a new query: the paths of the old one go
for (const id of ["sx", "sy", "gx", "gy"]) {
  $(id).addEventListener("input", () => {
    round++;
    setBusy($("run"), false);
    results = [];
    tbody.replaceChildren();
    draw();
    say(status, "Press Plan (or Enter) to plan with the typed cells.", "info");
  });
}

$("form").addEventListener("submit", (ev) => {
  ev.preventDefault();
  if (isBusy($("run"))) return; // a query is under way (Enter in a field submits too)
  plan(); // says what it does (or what is missing) before its first wait
  // on a phone's one column the map and its status line are under the form: bring them up
  status.closest("figure").scrollIntoView({ block: "nearest" });
});

function chosen() {
  return [...box.querySelectorAll("input:checked")].map((c) => c.value);
}

async function plan() {
  if (!grid) return;
  const start = point("s");
  const goal = point("g");
  if (!start || !goal) {
    say(status, "Give a start and a goal first (click the map, or type the cells).", "error");
    return;
  }
  const algorithms = chosen();
  if (!algorithms.length) {
    say(status, "Choose at least one algorithm.", "error");
    return;
  }
  const mine = ++round;
  const options = { corner_cutting: $("corner").checked };
  const weight = Number($("weight").value);
  if (weight && weight !== 1) options.weight = weight;
  results = algorithms.map((algorithm, k) => ({ algorithm, colour: PALETTE[k % PALETTE.length], answer: null, error: null }));
  showResults();
  say(status, `Planning with ${algorithms.join(", ")}…`, "busy");
  setBusy($("run"), true);
  let failed = null;
  try {
    for (const r of results) {
      try {
        r.answer = checkPlan(await postJSON("/plan", { map: grid.name, start, goal, algorithm: r.algorithm, ...options },
          { wait: PLAN_WAIT_MS }));
      } catch (err) {
        r.error = err;
        if (err.status === 401 || err.status === 403) {
          failed = err;
          break;
        }
      }
      if (mine !== round) return;
      showResults();
      draw();
    }
  } finally {
    if (mine === round) setBusy($("run"), false);
  }
  if (mine !== round) return;
  if (failed) {
    say(status, explain(failed, "Planning"), "error");
    $("token").focus();
    return;
  }
  const errors = results.filter((r) => r.error);
  if (errors.length) {
    // one sentence per distinct answer: a bad start is said once, not once per algorithm
    const byText = new Map();
    for (const r of errors) {
      const text = explain(r.error, "Planning").replace(/^Planning /, "");
      byText.set(text, [...(byText.get(text) || []), r.algorithm]);
    }
    const every = errors.length === results.length && byText.size === 1;
    say(status, [...byText].map(([text, names]) =>
      `${every ? "Planning" : names.join(", ")} ${text}${/[.!?]$/.test(text) ? "" : "."}`).join(" "), "error");
    focusFault(errors[0].error, { weight: "weight", start: "sx", goal: "gx" });
  } else {
    const found = results.filter((r) => r.answer.status === "found");
    say(status, `Planned (${start.join(", ")}) → (${goal.join(", ")}) with ${results.length} algorithm${results.length > 1 ? "s" : ""}: ` +
      `${found.length ? found.length : "none"} found a path.`, found.length ? "ok" : "error");
  }
  showResults();
  draw();
}

function showResults() {
  tbody.replaceChildren(...results.map((r) => {
    const a = r.answer;
    const swatch = h("span", { class: "swatch", style: `background:${r.colour}`, "aria-hidden": "true" });
    if (!a) {
      return h("tr", { dataset: { algorithm: r.algorithm } }, h("td", {}, swatch), h("td", {}, r.algorithm),
        h("td", { colspan: 5 }, r.error ? h("span", { class: "tag bad" }, r.error.detail) : h("span", { class: "pending" }, "planning…")));
    }
    const tag = a.status === "found" ? "tag ok" : "tag busy";
    return h("tr", { dataset: { algorithm: r.algorithm, cost: a.cost ?? "", expanded: a.expanded } },
      h("td", {}, swatch), h("td", {}, r.algorithm),
      h("td", {}, h("span", { class: tag }, a.status.replace("_", " "))),
      h("td", { class: "num" }, a.cost === null ? "–" : fmt(a.cost, 3)),
      h("td", { class: "num" }, fmt(a.expanded)),
      h("td", { class: "num" }, fmt(a.seconds * 1000, 2)),
      h("td", { class: "num" }, a.path.length));
  }));
}

async function start() {
  const all = await choices("PlanRequest", "algorithm", ["astar", "dijkstra", "bfs", "jps", "theta", "lazy_theta"]);
  box.replaceChildren(...all.filter((a) => !WORLD_ONLY.has(a)).map((a) =>
    h("label", { class: "check" }, h("input", { type: "checkbox", value: a, checked: DEFAULT_ON.has(a) }), a)));
  await listMaps();
}

/** The map list, and its first map shown; a failure says so with a way to ask again. */
async function listMaps() {
  say(status, "Loading the bundled maps…", "busy");
  if (!grid) note.show("Nothing to draw yet: reading the bundled maps…");
  let maps;
  try {
    maps = checkMaps(await getJSON("/maps"));
  } catch (err) {
    say(status, explain(err, "Reading the bundled maps"), "error", { retry: mayPass(err) ? listMaps : null });
    if (!grid) note.show("Nothing to draw: the bundled maps could not be read.");
    return;
  }
  if (!maps.length) {
    say(status, "This server has no bundled maps.", "error");
    note.show("Nothing to draw: this server has no bundled maps.");
    return;
  }
  mapSelect.replaceChildren(...maps.map((m) => h("option", { value: m.name }, `${m.name} (${m.width} × ${m.height})`)));
  mapSelect.disabled = false;
  await loadMap(mapSelect.value);
}

mapSelect.addEventListener("change", () => loadMap(mapSelect.value));
start().catch((err) => say(status, explain(err, "Loading the page"), "error"));
