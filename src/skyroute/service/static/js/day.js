// The delivery day page: a stored day's flight over the site (no-fly zones, confinement
// area, shops, customers), animated move by move, with the orders and the money so far.
//
// Reads GET /days, /site.geojson, /days/{date} and /days/{date}/flightpath.geojson; flies
// a day with POST /jobs/deliver (with replace, after a confirmation, over a stored flight
// that a day of invalid orders would otherwise keep) and follows GET /jobs/{id}; deletes
// a day without a flight (a mistyped date) with DELETE /days/{date}.

import { ApiError, bindToken, choices, explain, focusFault, getJSON, mayPass, postJSON, remove, sentence } from "./api.js";
import { JobFollower, jobId } from "./jobs.js";
import { Player } from "./player.js";
import { Answer, readable } from "./shape.js";
import { fmt, h, isBusy, pounds, say, setBusy } from "./ui.js";
import { MapView, bbox, dot, grow, label, localProjection } from "./view.js";

const $ = (id) => document.getElementById(id);
const status = $("status");
const siteStatus = $("site-status");
const jobStatus = $("job-status");
const select = $("date");
const tbody = document.querySelector("#orders tbody");

let site = null; // {zones: [[ring, ...]], confinement: ring|null, home, shops, customers} in lon/lat
let siteRead = null; // the site's read under way
let siteGone = false; // the server has no site (404): not asked again
let day = null; // the loaded day, see load()
let noDay = "Nothing to draw yet: reading the stored days…"; // why no day is shown
let proj = null;
let t = 0;
let loading = 0; // counts the days asked for: only the last one asked is shown

const view = new MapView($("map"), { draw: drawMap, empty: emptyWhy });
const player = new Player({
  play: $("play"), speed: $("speed"), slider: $("time"), output: $("time-text"),
  describe: (x) => (day ? `move ${Math.floor(x)} of ${day.moves}` : "move 0 of 0"),
  onTime: (x) => {
    t = x;
    update();
  },
  onEnd: () => {
    if (day) {
      const partly = customerPlaces(day.orders).filter(isPartly).length;
      say(status, `The flight of ${day.date} is over: ${day.report.orders_delivered} of ` +
        `${day.report.orders_placed} orders delivered, ${fmt(day.report.money_pct, 1)} % of the money ` +
        `in ${day.moves} moves` + (partly ? `; ${partly} customer place${partly > 1 ? "s" : ""} ` +
        "partly served (ringed)." : "."), "ok");
    }
  },
});

/** Why the map has nothing on it ("" when it has): no day, or a day with nothing to
 * place (no flight, no customer's place, no site). */
function emptyWhy() {
  if (!day) return noDay;
  if (day.coords.length || site || day.orders.some((o) => o.lonlat)) return "";
  return `Nothing to draw: ${day.date} has no flight and no customer's place, and no site is loaded.`;
}

/** GET /site.geojson's features as the map draws them (a point feature of another
 * geometry, or a kind the page does not know, is left out). */
function siteFrom(doc) {
  const s = { zones: [], confinement: null, home: null, shops: [], customers: [] };
  for (const f of new Answer("/site.geojson", "a delivery site (GeoJSON)").features(doc)) {
    const p = f.properties || {};
    const g = f.geometry;
    if (!g) continue;
    const point = g.type === "Point";
    if (p.kind === "no_fly_zone") {
      const polys = g.type === "Polygon" ? [g.coordinates] : g.type === "MultiPolygon" ? g.coordinates : [];
      for (const poly of polys) s.zones.push({ rings: poly, name: p.name || "" });
    } else if (p.kind === "confinement" && g.type === "Polygon") {
      s.confinement = g.coordinates[0];
    } else if (p.kind === "home" && point) {
      s.home = g.coordinates;
    } else if (p.kind === "shop" && point) {
      s.shops.push({ at: g.coordinates, name: String(p.name || "shop") });
    } else if (p.kind === "customer" && point) {
      s.customers.push({ at: g.coordinates, words: p.words || "" });
    }
  }
  return s;
}

/** GET /days as the list shows it: each with its date. */
function checkDays(days) {
  const a = new Answer("/days", "a list of days");
  return a.list(days, "", (d, f) => {
    a.object(d, f);
    a.string(d.date, `${f}.date`);
    a.maybe(d.money_pct, `${f}.money_pct`, a.number);
  });
}

/** GET /days/{date} (at ``where``) and its flightpath.geojson as show() reads them. */
function checkDay(detail, flight, where) {
  const a = new Answer(where, "a stored day");
  a.object(detail);
  const r = a.object(detail.report, "report");
  for (const k of ["orders_placed", "orders_delivered", "orders_invalid", "money_placed", "moves", "moves_left"]) {
    a.number(r[k], `report.${k}`);
  }
  a.maybe(r.money_pct, "report.money_pct", a.number);
  a.maybe(r.settings, "report.settings", a.object);
  a.list(detail.deliveries, "deliveries", (d, f) => {
    a.object(d, f);
    a.string(d.order_no, `${f}.order_no`);
    a.number(d.cost_in_pence, `${f}.cost_in_pence`);
  });
  a.list(detail.orders, "orders", (o, f) => {
    a.object(o, f);
    a.string(o.order_no, `${f}.order_no`);
    a.string(o.status, `${f}.status`);
    a.list(o.items, `${f}.items`);
    a.maybe(o.value, `${f}.value`, a.number);
    a.maybe(o.lonlat, `${f}.lonlat`, a.position);
  });
  const g = new Answer(`${where}/flightpath.geojson`, "a day's flight (GeoJSON)");
  const features = g.features(flight);
  if (!features.length) g.fail("features", "a list of one flight");
  g.maybe(features[0].geometry, "features[0].geometry", (geo, f) => {
    if (geo.type !== "LineString") g.fail(`${f}.type`, "LineString");
  });
  const props = features[0].properties || {};
  g.maybe(props.orders, "features[0].properties.orders", g.list);
  g.maybe(props.moves, "features[0].properties.moves", g.number);
}

/** Fill the day list (``wanted`` chosen when stored); false when there is none to show.
 * A failure says so with a way to ask again (``retry``: the list and a day shown). */
async function listDays(wanted = null, retry = () => showDays(wanted)) {
  let days;
  try {
    days = checkDays(await getJSON("/days"));
  } catch (err) {
    say(status, explain(err, "Reading the stored days"), "error", { retry: mayPass(err) ? retry : null });
    if (!day) sayNoDay("Nothing to draw: the stored days could not be read.");
    return false;
  }
  if (!days.length) {
    select.replaceChildren(h("option", {}, "no stored days"));
    select.disabled = true;
    showNoDay("Nothing to draw: the store holds no delivery day yet.");
    // a day is flown from the store's orders: a fresh store has none to fly
    say(status, "The store holds no delivery day yet. Import a day's orders (skyroute db import " +
      "DIR --db URL) and fly it below, or fly it with skyroute deliver DATE --data DIR --db URL.", "info");
    return false;
  }
  select.replaceChildren(...days.map((d) => h("option", { value: d.date },
    `${d.date} · ${d.money_pct === null ? "no orders" : `${fmt(d.money_pct, 1)} %`}`)));
  select.disabled = false;
  if (wanted && days.some((d) => d.date === wanted)) select.value = wanted;
  return true;
}

async function start() {
  const methods = await choices("DeliverJob", "method", ["milp", "greedy"]);
  $("method").replaceChildren(...methods.map((m) => h("option", { value: m }, m)));
  select.addEventListener("change", () => load(select.value));
  const job = jobs.remembered(); // a day flown before a reload: followed after the list
  if (job) {
    setBusy($("start"), true);
    say(jobStatus, "Following the day being flown since before this page was loaded…", "busy");
  }
  await showDays(new URLSearchParams(location.hash.slice(1)).get("date"), { linked: true });
  if (job) await jobs.follow(job);
}

/** The day list and a day (with the site): ``wanted`` when stored, else the newest
 * (and, when ``linked`` (the page's address named it), a note that it is not stored). */
async function showDays(wanted = null, { linked = false } = {}) {
  if (!(await listDays(wanted, () => showDays(wanted, { linked })))) return;
  // a link to a day the store does not hold says so, not just shows another day
  await load(select.value, linked && wanted && select.value !== wanted ? `The link names ${wanted}, ` +
    `which is not a stored day; this is ${select.value}. ` : "");
}

/** The site read, if it is not yet (again after a failure that may pass: by the next
 * day shown, or the site line's Try again). It never fails: a failure is said on the
 * site's own line (the day's line, said after it, took its place), and the day is drawn
 * without it. */
function siteReady() {
  if (site || siteGone) return Promise.resolve();
  siteRead = siteRead || readSite().finally(() => {
    siteRead = null;
  });
  return siteRead;
}

async function readSite() {
  try {
    site = siteFrom(await getJSON("/site.geojson"));
    say(siteStatus, "");
  } catch (err) {
    site = null;
    if (err instanceof ApiError && err.status === 404) {
      siteGone = true;
      say(siteStatus, "No site to draw (the server was started without --data or --source): " +
        "the flight is shown alone.", "info");
    } else {
      say(siteStatus, `${sentence(explain(err, "Reading the site"))} The day is drawn without it.`, "error",
        { retry: mayPass(err) ? retrySite : null });
    }
  }
}

async function retrySite() {
  say(siteStatus, "Reading the site…", "busy");
  await siteReady();
  if (site && day) place(); // the day shown, now over its site
}

// -- flying a day as a job -------------------------------------------------------
const jobs = new JobFollower({
  key: "skyroute.dayJob", bar: $("progress"), line: jobStatus, button: $("start"),
  what: "the day", done: "The day is flown and stored.",
  // a day whose every order is invalid now keeps its stored flight: the way on is here
  hint: (error) => (/replace=true/.test(error || "") ? "To store the day as flown now, " +
    "over its stored flight, tick “Replace a kept flight” and fly it again." : ""),
  onDone: async (r) => {
    if (r.days_with_orders === 0) {
      // the job stores the day even so (a day of no orders): not "flown", and what to do
      say(jobStatus, `Nothing was flown: the store holds no orders of ${r.from}. Import them ` +
        "(skyroute db import DIR --db URL) and fly the day again; the day stored without a " +
        "flight can be deleted above.", "error");
    }
    if (!(await listDays(r.from))) return;
    await load(select.value);
  },
});
bindToken($("token"));

$("job").addEventListener("submit", async (ev) => {
  ev.preventDefault();
  if (isBusy($("start"))) return; // a day is being flown (Enter in a field submits too)
  const date = $("job-date").value;
  if (!date) {
    say(jobStatus, "Give the date to fly first.", "error");
    $("job-date").focus();
    return;
  }
  const replace = $("replace").checked;
  // replace stores a flight that delivers nothing over one that delivered: asked first
  // (a day not stored has no flight to lose)
  if (replace && [...select.options].some((o) => o.value === date) &&
      !confirm(`Fly ${date} again and store the new flight over its stored one, even if ` +
        "every order is invalid now and it delivers nothing? The stored flight and its " +
        "deliveries are replaced; this cannot be undone.")) {
    say(jobStatus, `Not flown: the stored flight of ${date} is kept.`, "info");
    return;
  }
  setBusy($("start"), true);
  $("progress").value = 0;
  say(jobStatus, `Submitting ${date}…`, "busy");
  let id;
  try {
    id = jobId(await postJSON("/jobs/deliver", { date, method: $("method").value, replace }), "/jobs/deliver");
  } catch (err) {
    say(jobStatus, explain(err, `Flying ${date}`), "error");
    focusFault(err, { date: "job-date", method: "method", replace: "replace" });
    setBusy($("start"), false);
    return;
  }
  $("replace").checked = false; // once: the next day flown keeps a stored flight again
  await jobs.start(id);
});

async function load(date, note = "") {
  player.pause();
  const mine = ++loading;
  say(status, `Loading ${date}…`, "busy");
  const where = `/days/${encodeURIComponent(date)}`;
  let detail, flight;
  try {
    // the site (when not yet read) asked beside the day: the day is drawn over it
    [detail, flight] = await Promise.all([getJSON(where), getJSON(`${where}/flightpath.geojson`), siteReady()]);
    checkDay(detail, flight, where);
  } catch (err) {
    if (mine !== loading) return;
    say(status, explain(err, `Reading ${date}`), "error", { retry: mayPass(err) ? () => load(date, note) : null });
    if (!day) sayNoDay(`Nothing to draw: ${date} could not be read.`);
    // a day deleted since the list was read goes from it; the list shows the day shown
    // again (left on the failed one, choosing that one again asked nothing)
    if (err instanceof ApiError && err.status === 404) [...select.options].find((o) => o.value === date)?.remove();
    if (day) select.value = day.date;
    return;
  }
  if (mine !== loading) return; // another day was chosen while this one was read
  try {
    show(date, detail, flight, note);
  } catch (err) {
    // a shape checkDay let pass: said in skyroute's words, not a page left on
    // "Loading…" with an exception in the console
    showNoDay(`Nothing to draw: ${date} could not be read.`);
    say(status, explain(readable(err, where, "a stored day"), `Reading ${date}`), "error");
  }
}

/** Show the day ``date`` from its GET /days/{date} and flightpath.geojson answers. */
function show(date, detail, flight, note) {
  const feature = flight.features[0];
  const coords = feature.geometry ? feature.geometry.coordinates : [];
  const props = feature.properties || {};
  const moveOrders = props.orders || [];
  const moves = props.moves ?? Math.max(coords.length - 1, 0);
  // an order is delivered by its last move (the hover at the customer)
  const doneAt = new Map();
  moveOrders.forEach((no, k) => no && doneAt.set(no, k + 1));
  const cost = new Map(detail.deliveries.map((d) => [d.order_no, d.cost_in_pence]));
  const deliveries = detail.deliveries.map((d) => ({ ...d, at: doneAt.get(d.order_no) ?? moves }));
  const battery = detail.report.settings && detail.report.settings.battery
    ? detail.report.settings.battery : detail.report.moves + detail.report.moves_left;
  day = { date, report: detail.report, orders: detail.orders, deliveries, coords, moves, battery, cost, doneAt };
  history.replaceState(null, "", `#date=${date}`);
  if ([...select.options].some((o) => o.value === date)) select.value = date; // (asked again)
  place();
  fillOrders();
  player.load(moves, 1);
  // a day without a flight (a mistyped date, no orders to fly) may be deleted
  $("delete-row").hidden = moves > 0 || deliveries.length > 0;
  if (moves) {
    say(status, `${note}${date}: ${moves} moves, ${detail.report.orders_delivered} of ${detail.report.orders_placed} ` +
      `orders delivered, ${fmt(detail.report.money_pct, 1)} % of the money. Press Play to fly it.`, note ? "info" : "ok");
  } else {
    say(status, `${note}${date}: the drone did not fly (${detail.report.orders_placed
      ? `none of the ${detail.report.orders_placed} orders could be delivered` : "no orders were placed"}), ` +
      "so there is nothing to play.", "info");
  }
  $("s-final").textContent = `Report: ${detail.report.orders_invalid} invalid orders, ` +
    `${detail.report.moves_left} moves of battery left at the end.`;
}

/** Say ``why`` on the empty map (no day is shown; the address keeps the day linked). */
function sayNoDay(why) {
  noDay = why;
  view.render();
}

/** The plane of the day shown: metres around the middle of everything drawn (its
 * flight and customers, the site), fitted to the map; drawn again. */
function place() {
  const ll = [...day.coords];
  if (site) {
    if (site.confinement) ll.push(...site.confinement);
    for (const z of site.zones) ll.push(...z.rings[0]);
    for (const s of site.shops) ll.push(s.at);
  }
  for (const o of day.orders) if (o.lonlat) ll.push(o.lonlat);
  if (!ll.length) ll.push([0, 0]);
  const b = bbox(ll);
  proj = localProjection((b[0] + b[2]) / 2, (b[1] + b[3]) / 2);
  day.xy = day.coords.map(proj.fwd);
  view.setBounds(grow(bbox(ll.map(proj.fwd)), 0.03, 5));
}

/** The page without a day (``why``: the store holds none, it could not be read): an
 * empty map saying so, an empty table and numbers. */
function showNoDay(why) {
  noDay = why;
  day = null;
  player.load(0, 1);
  tbody.replaceChildren();
  for (const id of ["s-moves", "s-orders", "s-money", "s-pct", "s-battery"]) $(id).textContent = "–";
  $("s-final").textContent = "";
  $("delete-row").hidden = true;
  history.replaceState(null, "", location.pathname);
  view.render();
}

// -- deleting a day without a flight (DELETE /days/{date}) ------------------------
$("delete").addEventListener("click", async () => {
  const button = $("delete");
  if (isBusy(button) || !day) return;
  const date = day.date;
  if (!confirm(`Delete the stored day ${date} from the store? The drone did not fly it; ` +
    "its orders, if any, stay.")) return;
  const dates = [...select.options].map((o) => o.value);
  const k = dates.indexOf(date);
  const next = dates[k + 1] ?? dates[k - 1] ?? null; // shown next: its neighbour in the list
  setBusy(button, true);
  say(status, `Deleting ${date}…`, "busy");
  let note = `Deleted ${date}. `;
  try {
    await remove(`/days/${encodeURIComponent(date)}`);
  } catch (err) {
    setBusy(button, false);
    if (!(err instanceof ApiError && err.status === 404)) {
      say(status, explain(err, `Deleting ${date}`), "error");
      focusFault(err); // the Token field for a 401 or 403
      return;
    }
    note = `${date} was no longer stored. `; // deleted meanwhile (another tab): the list is old
  }
  setBusy(button, false);
  // the button goes with the day: the focus goes to the day list (or, with no day left,
  // to the date to fly), not to the page's body
  if (await listDays(next)) {
    await load(select.value, note);
    select.focus();
  } else {
    say(status, `${note}The store holds no delivery day now: fly one below.`, "ok");
    $("job-date").focus();
  }
});

function fillOrders() {
  const rank = { delivered: 0, not_delivered: 1, invalid: 2 };
  const rows = [...day.orders].sort((a, b) =>
    (rank[a.status] ?? 3) - (rank[b.status] ?? 3) ||
    (day.doneAt.get(a.order_no) ?? 0) - (day.doneAt.get(b.order_no) ?? 0) ||
    a.order_no.localeCompare(b.order_no));
  day.rows = [];
  tbody.replaceChildren(...rows.map((o) => {
    const result = o.status === "delivered" ? h("span", { class: "tag ok" }, "delivered")
      : o.status === "invalid" ? h("span", { class: "tag bad", title: o.reason || "" }, `invalid: ${o.reason || "?"}`)
        : h("span", { class: "tag busy" }, "not delivered");
    const flown = h("td", {});
    const tr = h("tr", { dataset: { order: o.order_no, status: o.status } },
      h("td", {}, h("code", {}, o.order_no)), h("td", {}, o.deliver_to),
      h("td", { class: "num" }, o.items.length), h("td", { class: "num" }, pounds(o.value)),
      h("td", {}, result), flown);
    const at = o.status === "delivered" ? day.doneAt.get(o.order_no) : undefined;
    day.rows.push({ tr, flown, at, done: null });
    return tr;
  }));
}

function update() {
  if (!day) return;
  const k = Math.floor(t);
  let n = 0;
  let money = 0;
  for (const d of day.deliveries) {
    if (d.at <= k) {
      n += 1;
      money += d.cost_in_pence;
    }
  }
  $("s-moves").textContent = `${k} of ${day.moves}`;
  $("s-orders").textContent = `${n} of ${day.report.orders_placed}`;
  $("s-money").textContent = `${pounds(money)} of ${pounds(day.report.money_placed)}`;
  $("s-pct").textContent = day.report.money_placed ? `${fmt((100 * money) / day.report.money_placed, 1)} %` : "–";
  $("s-battery").textContent = `${day.battery - k} moves`;
  for (const r of day.rows) {
    const done = r.at !== undefined && r.at <= k;
    if (done === r.done) continue;
    r.done = done;
    r.tr.classList.toggle("done", done);
    r.flown.replaceChildren(r.at === undefined ? "–"
      : done ? `✓ move ${r.at}` : h("span", { class: "pending" }, `at move ${r.at}`));
  }
  view.render();
}

function drawMap(ctx, v) {
  if (!day) return;
  const P = (ll) => v.px(proj.fwd(ll));
  if (site) {
    if (site.confinement) {
      v.path(site.confinement.map(proj.fwd), true);
      ctx.fillStyle = "#ffffff";
      ctx.fill();
      ctx.setLineDash([6, 4]);
      ctx.strokeStyle = "#5b6475";
      ctx.lineWidth = 1.5;
      ctx.stroke();
      ctx.setLineDash([]);
    }
    for (const z of site.zones) {
      ctx.beginPath();
      for (const ring of z.rings) {
        ring.forEach((p, i) => {
          const [x, y] = P(p);
          if (i) ctx.lineTo(x, y);
          else ctx.moveTo(x, y);
        });
        ctx.closePath();
      }
      ctx.fillStyle = "rgba(214, 69, 65, .22)";
      ctx.fill("evenodd");
      ctx.strokeStyle = "#b3261e";
      ctx.lineWidth = 1;
      ctx.stroke();
    }
  }
  // customers of the day, one dot a place (several orders may share one): blue, green
  // once its delivered orders are all delivered, grey when none of its orders is served;
  // a grey ring marks a place where some orders are served and some are not
  const k = Math.floor(t);
  for (const place of customerPlaces(day.orders)) {
    const served = place.orders.filter(o => o.status === "delivered");
    const done = served.every(o => (day.doneAt.get(o.order_no) ?? Infinity) <= k);
    const at = P(place.lonlat);
    const partly = isPartly(place);
    dot(ctx, at, 4.5, !served.length ? "#8a8f99" : done ? "#1b7a3d" : "#0072b2",
        partly ? "#8a8f99" : "#fff");
    if (partly) dot(ctx, at, 7, "rgba(0,0,0,0)", "#5b6475");
  }
  if (site) {
    for (const s of site.shops) {
      const [x, y] = P(s.at);
      ctx.fillStyle = "#e69f00";
      ctx.strokeStyle = "#fff";
      ctx.lineWidth = 1.5;
      ctx.fillRect(x - 5, y - 5, 10, 10);
      ctx.strokeRect(x - 5, y - 5, 10, 10);
      if (v.width > 500) label(ctx, s.name, [x + 8, y + 4], { font: "11px system-ui, sans-serif" });
    }
    if (site.home) {
      const [x, y] = P(site.home);
      ctx.fillStyle = "#1d2433";
      ctx.beginPath();
      ctx.moveTo(x, y - 8);
      ctx.lineTo(x + 7, y);
      ctx.lineTo(x + 5, y);
      ctx.lineTo(x + 5, y + 6);
      ctx.lineTo(x - 5, y + 6);
      ctx.lineTo(x - 5, y);
      ctx.lineTo(x - 7, y);
      ctx.closePath();
      ctx.fill();
      label(ctx, "home", [x + 9, y + 4], { font: "bold 11px system-ui, sans-serif" });
    }
  }
  // the flight so far, and the drone between two moves
  const xy = day.xy;
  if (xy.length) {
    const i = Math.min(k, xy.length - 1);
    const f = t - k;
    const here = i + 1 < xy.length
      ? [xy[i][0] + (xy[i + 1][0] - xy[i][0]) * f, xy[i][1] + (xy[i + 1][1] - xy[i][1]) * f] : xy[i];
    v.path([...xy.slice(0, i + 1), here]);
    ctx.strokeStyle = "#d55e00";
    ctx.lineWidth = 1.6;
    ctx.lineJoin = "round";
    ctx.stroke();
    const [x, y] = v.px(here);
    ctx.beginPath();
    ctx.arc(x, y, 7, 0, 2 * Math.PI);
    ctx.fillStyle = "#d55e00";
    ctx.fill();
    ctx.strokeStyle = "#fff";
    ctx.lineWidth = 2;
    ctx.stroke();
    ctx.beginPath();
    ctx.arc(x, y, 2.5, 0, 2 * Math.PI);
    ctx.fillStyle = "#fff";
    ctx.fill();
  }
}

start().catch((err) => say(status, explain(err, "Loading the page"), "error"));

/** The day's orders grouped by their customer's place: [{lonlat, orders}], in order of
 * first appearance (orders without a place left out). */
function customerPlaces(orders) {
  const places = new Map();
  for (const o of orders) {
    if (!o.lonlat) continue;
    const key = o.lonlat.join(",");
    if (!places.has(key)) places.set(key, { lonlat: o.lonlat, orders: [] });
    places.get(key).orders.push(o);
  }
  return [...places.values()];
}

/** Some of a place's valid orders delivered and some not (invalid orders never count,
 * as on the day's PNG). */
function isPartly(place) {
  const valid = place.orders.filter((o) => o.status !== "invalid");
  const served = valid.filter((o) => o.status === "delivered").length;
  return served > 0 && served < valid.length;
}
