// A map on a canvas without tiles: a plane in metres (x east, y north, north up) fitted
// to the canvas, with a scale bar and a north arrow in a key strip under it (never over
// what is plotted); and lon/lat to local metres.

const WGS84_A = 6378137.0;
const WGS84_F = 1 / 298.257223563;

/** Lon/lat <-> east/north metres around (lon0, lat0): the local tangent plane to first
 * order (the ellipsoid's radii of curvature at lat0); within a few kilometres of the
 * origin it is off by well under a pixel of any map drawn here. */
export function localProjection(lon0, lat0) {
  const e2 = WGS84_F * (2 - WGS84_F);
  const phi = (lat0 * Math.PI) / 180;
  const w = 1 - e2 * Math.sin(phi) ** 2;
  const kx = ((WGS84_A / Math.sqrt(w)) * Math.cos(phi) * Math.PI) / 180; // metres per degree of lon
  const ky = ((WGS84_A * (1 - e2)) / w ** 1.5 * Math.PI) / 180; // metres per degree of lat
  return {
    lon0, lat0,
    fwd: ([lon, lat]) => [(lon - lon0) * kx, (lat - lat0) * ky],
    inv: ([x, y]) => [lon0 + x / kx, lat0 + y / ky],
  };
}

/** [minx, miny, maxx, maxy] of points [[x, y], ...] (grown from ``into``). */
export function bbox(points, into = [Infinity, Infinity, -Infinity, -Infinity]) {
  const b = into.slice();
  for (const [x, y] of points) {
    if (x < b[0]) b[0] = x;
    if (y < b[1]) b[1] = y;
    if (x > b[2]) b[2] = x;
    if (y > b[3]) b[3] = y;
  }
  return b;
}

export function grow(b, share = 0.04, least = 1) {
  const m = Math.max((b[2] - b[0]) * share, (b[3] - b[1]) * share, least);
  return [b[0] - m, b[1] - m, b[2] + m, b[3] + m];
}

const PAD = 14; // CSS pixels round the plotted region
// The key strip under the plotted region: the scale bar on its left, the north arrow on
// its right. Drawn over the plot's corners (as they were) they hid what lay there: on a
// phone the arrow covered a customer of the README's day, the scale bar an airport's
// runway.
export const KEY = 30; // (the planner's canvas has the same strip)

/** A line over a map's plotted region (``canvas`` above its key strip of ``key`` px)
 * saying why there is nothing on it: an empty canvas read as a page that failed to
 * draw. A paragraph after the canvas (read after the map's label by a screen reader),
 * placed over it; the canvas's figure is its positioned parent (viewer.css). */
export class EmptyNote {
  constructor(canvas, key = KEY) {
    this.canvas = canvas;
    this.key = key;
    this.text = "";
    this.el = document.createElement("p");
    this.el.className = "map-empty";
    this.el.hidden = true;
    canvas.after(this.el);
  }

  /** Show ``text`` over the canvas (the one shown: placed again), or nothing (null, ""). */
  show(text = this.text) {
    const el = this.el;
    this.text = text || "";
    if (!text) {
      el.hidden = true;
      return;
    }
    if (el.textContent !== text) el.textContent = text;
    el.hidden = false;
    const c = this.canvas;
    Object.assign(el.style, {
      left: `${c.offsetLeft}px`, top: `${c.offsetTop}px`, width: `${c.offsetWidth}px`,
      height: `${Math.max(c.offsetHeight - this.key, 0)}px`,
    });
  }
}

/** A canvas showing the plane region ``bounds`` (x east, y north) at the largest scale
 * that fits above the key strip, redrawn by ``draw(ctx, view)`` on ``render()`` and
 * whenever its width changes. While ``empty()`` gives a reason (nothing loaded yet, or
 * nothing to load: a sentence, "" or null when there is something to draw) the map says
 * it (``EmptyNote``) and its key strip is left empty: a scale bar and a north arrow over
 * an empty map measure and orient nothing, and read as a map that failed to draw. */
export class MapView {
  constructor(canvas, { draw, empty = () => "", maxShare = 0.72, minHeight = 240, unit = "m", north = true } = {}) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.draw = draw;
    this.empty = empty;
    this.note = new EmptyNote(canvas);
    this.maxShare = maxShare;
    this.minHeight = minHeight;
    this.unit = unit;
    this.north = north;
    this.bounds = [0, 0, 1, 1];
    this.width = 0;
    this.scale = 1;
    new ResizeObserver(() => {
      if (canvas.clientWidth !== this.width) this.resize();
    }).observe(canvas.parentElement);
  }

  setBounds(bounds) {
    this.bounds = bounds;
    this.resize();
  }

  resize() {
    const [x0, y0, x1, y1] = this.bounds;
    const w = this.canvas.clientWidth || 300;
    const ratio = (y1 - y0) / Math.max(x1 - x0, 1e-12);
    const most = Math.max(this.minHeight, window.innerHeight * this.maxShare);
    const hpx = Math.round(Math.min(Math.max((w - 2 * PAD) * ratio + 2 * PAD + KEY, this.minHeight), most));
    const dpr = window.devicePixelRatio || 1;
    this.canvas.style.height = `${hpx}px`;
    this.canvas.width = Math.round(w * dpr);
    this.canvas.height = Math.round(hpx * dpr);
    this.width = w;
    this.height = hpx;
    this.dpr = dpr;
    const high = hpx - KEY; // the plotted region's height, padding included
    this.scale = Math.min((w - 2 * PAD) / Math.max(x1 - x0, 1e-12), (high - 2 * PAD) / Math.max(y1 - y0, 1e-12));
    this.ox = (w - this.scale * (x1 - x0)) / 2;
    this.oy = (high - this.scale * (y1 - y0)) / 2;
    this.render();
  }

  /** Plane point -> CSS pixel. */
  px([x, y]) {
    return [this.ox + (x - this.bounds[0]) * this.scale, this.oy + (this.bounds[3] - y) * this.scale];
  }

  /** CSS pixel -> plane point. */
  at(px, py) {
    return [this.bounds[0] + (px - this.ox) / this.scale, this.bounds[3] - (py - this.oy) / this.scale];
  }

  /** The plane point under a mouse event. */
  eventPoint(ev) {
    const r = this.canvas.getBoundingClientRect();
    return this.at(ev.clientX - r.left, ev.clientY - r.top);
  }

  render() {
    const ctx = this.ctx;
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.clearRect(0, 0, this.width, this.height);
    ctx.fillStyle = "#fbfcfd";
    ctx.fillRect(0, 0, this.width, this.height);
    if (this.draw) this.draw(ctx, this);
    const why = this.empty();
    this.note.show(why);
    if (why) return;
    drawScaleBar(ctx, this.scale, this.unit, 12, this.height - 8);
    if (this.north) drawNorthArrow(ctx, this.width - 14, this.height - KEY + 4);
  }

  /** Stroke or fill a ring or line of plane points. */
  path(points, close = false) {
    const ctx = this.ctx;
    ctx.beginPath();
    points.forEach((p, i) => {
      const [x, y] = this.px(p);
      if (i) ctx.lineTo(x, y);
      else ctx.moveTo(x, y);
    });
    if (close) ctx.closePath();
  }
}

function niceLength(most) {
  const p = 10 ** Math.floor(Math.log10(most));
  for (const m of [5, 2, 1]) if (m * p <= most) return m * p;
  return p;
}

/** A scale bar at (x, y) (its bottom left), about 120 px long at most. */
export function drawScaleBar(ctx, pxPerUnit, unit, x, y) {
  if (!(pxPerUnit > 0) || !Number.isFinite(pxPerUnit)) return;
  const len = niceLength(120 / pxPerUnit);
  const w = len * pxPerUnit;
  const label = unit === "m" && len >= 1000 ? `${len / 1000} km` : `${len} ${unit}`;
  ctx.save();
  ctx.font = "12px system-ui, sans-serif";
  const tw = ctx.measureText(label).width;
  ctx.fillStyle = "rgba(255,255,255,.85)";
  ctx.fillRect(x - 4, y - 20, Math.max(w, tw) + 8, 24);
  ctx.strokeStyle = "#1d2433";
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.moveTo(x, y - 6);
  ctx.lineTo(x, y);
  ctx.lineTo(x + w, y);
  ctx.lineTo(x + w, y - 6);
  ctx.stroke();
  ctx.fillStyle = "#1d2433";
  ctx.fillText(label, x, y - 8);
  ctx.restore();
}

/** A north arrow of 20 px by 22 px, its right edge at x and its top at y: "N" and an
 * arrow pointing up. */
export function drawNorthArrow(ctx, x, y) {
  ctx.save();
  ctx.fillStyle = "#1d2433";
  const ax = x - 5; // the arrow's middle
  ctx.beginPath();
  ctx.moveTo(ax, y);
  ctx.lineTo(ax + 5, y + 20);
  ctx.lineTo(ax, y + 16);
  ctx.lineTo(ax - 5, y + 20);
  ctx.closePath();
  ctx.fill();
  ctx.font = "bold 12px system-ui, sans-serif";
  ctx.textAlign = "right";
  ctx.fillText("N", ax - 7, y + 17);
  ctx.restore();
}

/** A filled circle marker with an outline. */
export function dot(ctx, [x, y], r, fill, stroke = "#fff") {
  ctx.beginPath();
  ctx.arc(x, y, r, 0, 2 * Math.PI);
  ctx.fillStyle = fill;
  ctx.fill();
  if (stroke) {
    ctx.lineWidth = 1.5;
    ctx.strokeStyle = stroke;
    ctx.stroke();
  }
}

/** A short label with a white halo. */
export function label(ctx, text, [x, y], { align = "left", font = "12px system-ui, sans-serif", color = "#1d2433" } = {}) {
  ctx.save();
  ctx.font = font;
  ctx.textAlign = align;
  ctx.lineWidth = 3;
  ctx.strokeStyle = "rgba(255,255,255,.9)";
  ctx.strokeText(text, x, y);
  ctx.fillStyle = color;
  ctx.fillText(text, x, y);
  ctx.restore();
}
