// A fleet run's label in the run list: the whole label (when the run was stored, its
// scenario, hours, seed and packages delivered) is wider than the list on every screen
// (491 px of text in a list 287 px wide beside the map, 302 px on a phone), so the list
// shows the longest shorter form that fits its width and keeps the whole one as the
// option's tooltip; the run shown has every part in the panel's numbers, which wrap.

import { fmt } from "./ui.js";

const MONTHS = ["Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"];
const ARROW = 24; // a closed list's arrow and the gap before it, CSS px
let pen = null; // a canvas's 2D context, measuring text

/** When ``iso`` was, in the browser's time zone: ``whole`` (2026-11-28 02:17:18),
 * ``short`` (28 Nov 02:17; the year too where it is not this one) and ``seconds`` (28
 * Nov 02:17:18); null without it. */
export function storedAt(iso) {
  const d = new Date(iso);
  if (!iso || Number.isNaN(d.getTime())) return null;
  const two = (n) => String(n).padStart(2, "0");
  const time = `${two(d.getHours())}:${two(d.getMinutes())}`;
  const year = d.getFullYear() === new Date().getFullYear() ? "" : ` ${d.getFullYear()}`;
  const day = `${d.getDate()} ${MONTHS[d.getMonth()]}${year}`;
  return {
    whole: `${d.getFullYear()}-${two(d.getMonth() + 1)}-${two(d.getDate())} ${time}:${two(d.getSeconds())}`,
    short: `${day} ${time}`,
    seconds: `${day} ${time}:${two(d.getSeconds())}`,
  };
}

/** A run's parts (a GET /fleet/runs item): each a text, or null where the run has none. */
export function runParts(r) {
  const p = r.params || {};
  const rep = r.report || {};
  const hours = p.hours ?? rep.simulated_hours;
  const seed = p.seed ?? (rep.settings || {}).seed;
  return {
    at: storedAt(r.created), // runs of the same settings differ by it
    scenario: String(r.scenario || "scenario"),
    hours: hours === undefined ? null : `${fmt(hours, 2)} h`,
    seed: seed === undefined ? null : `seed ${seed}`,
    delivered: rep.delivered === undefined ? null : `${rep.delivered}/${rep.offered} delivered`,
  };
}

const join = (...parts) => parts.filter(Boolean).join(" · ");

/** The run's whole label, without when it was stored unless ``when``. */
export function runLabel(r, { when = true } = {}) {
  const p = runParts(r);
  return join(when && p.at && p.at.whole, p.scenario, p.hours, p.seed, p.delivered);
}

/** Whether a text fits the closed list ``select`` (its font; its width less its padding
 * and arrow). */
export function fitsIn(select) {
  const cs = getComputedStyle(select);
  pen = pen || document.createElement("canvas").getContext("2d");
  pen.font = cs.font;
  const room = select.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight) - ARROW;
  return (text) => pen.measureText(text).width <= room;
}

/** ``{whole, short}``: the run's whole label and the longest of its forms that ``fits``:
 * whole; without the packages delivered; with the short time; without the hours; then
 * with the scenario's name cut (…) to the longest start that fits, one letter at least.
 * ``alike`` (0, 1, 2): how many times its short label was one of another run's: the
 * short time then has its seconds, and then the run's id follows (in the whole label
 * too). */
export function runLabels(r, fits, alike = 0) {
  const p = runParts(r);
  const extra = alike > 1 ? [`run ${String(r.id).slice(0, 8)}`] : [];
  const whole = join(p.at && p.at.whole, p.scenario, p.hours, p.seed, p.delivered, ...extra);
  const short = p.at && (alike ? p.at.seconds : p.at.short);
  const forms = [whole, join(p.at && p.at.whole, p.scenario, p.hours, p.seed, ...extra),
    join(short, p.scenario, p.hours, p.seed, ...extra), join(short, p.scenario, p.seed, ...extra)];
  const fit = forms.find(fits);
  if (fit) return { whole, short: fit };
  const cut = (n) => join(short, `${p.scenario.slice(0, n)}…`, p.seed, ...extra);
  let lo = 1;
  let hi = p.scenario.length - 1;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (fits(cut(mid))) lo = mid;
    else hi = mid - 1;
  }
  return { whole, short: cut(lo) };
}
