// The server's answers checked for the shape the pages read before a page uses them: JSON
// of another shape (another server's, a proxy's, an older skyroute's) is a ShapeError
// whose one line names the endpoint and the field ("the server's answer to
// /days/2024-01-03 is not a stored day: "deliveries" is not a list"), said as the pages
// say every failure; never the browser's own TypeError from deep inside a drawing.

import { ApiError } from "./api.js";

/** An answer of 2xx whose JSON is not of the shape asked for: an ApiError as the one
 * for an answer that is not JSON at all, so the pages say it, and offer Try again, alike. */
export class ShapeError extends ApiError {
  constructor(detail) {
    super(200, detail);
  }
}

/** One answer under check: ``where`` the endpoint asked (``/days/2024-01-03``), ``what``
 * what its answer should be ("a stored day"). Each check returns the value it passed;
 * ``field`` is where in the answer (``deliveries[3].order_no``, "" for the whole). */
export class Answer {
  constructor(where, what) {
    this.where = where;
    this.what = what;
  }

  fail(field, kind) {
    const head = `the server's answer to ${this.where} is not ${this.what}`;
    throw new ShapeError(field ? `${head}: "${field}" is not ${kind}` : head);
  }

  object(v, field = "") {
    if (v === null || typeof v !== "object" || Array.isArray(v)) this.fail(field, "an object");
    return v;
  }

  /** A list; ``each(item, field)`` checks every item. */
  list(v, field = "", each = null) {
    if (!Array.isArray(v)) this.fail(field, "a list");
    if (each) v.forEach((x, i) => each.call(this, x, `${field}[${i}]`));
    return v;
  }

  string(v, field) {
    if (typeof v !== "string") this.fail(field, "a string");
    return v;
  }

  number(v, field) {
    if (typeof v !== "number" || !Number.isFinite(v)) this.fail(field, "a number");
    return v;
  }

  /** ``check(v, field)`` unless ``v`` is null or absent. */
  maybe(v, field, check) {
    return v === null || v === undefined ? v : check.call(this, v, field);
  }

  /** A GeoJSON position (or a cell, a point): a list of two numbers or more. */
  position(v, field) {
    if (!Array.isArray(v) || v.length < 2 || !v.every((x) => typeof x === "number" && Number.isFinite(x))) {
      this.fail(field, "a point (a list of numbers)");
    }
    return v;
  }

  positions(v, field) {
    return this.list(v, field, (p, f) => this.position(p, f));
  }

  /** A GeoJSON feature collection: its features, each an object whose geometry (or
   * null) has coordinates of its type's depth (Point 0, LineString 1, Polygon 2,
   * MultiPolygon 3); other types are left to the page, which draws none. */
  features(doc) {
    this.object(doc);
    return this.list(doc.features, "features", (f, field) => {
      this.object(f, field);
      this.maybe(f.properties, `${field}.properties`, this.object);
      this.maybe(f.geometry, `${field}.geometry`, (g, gf) => {
        this.object(g, gf);
        const depth = { Point: 0, LineString: 1, Polygon: 2, MultiPolygon: 3 }[g.type];
        if (depth !== undefined) this.nested(g.coordinates, `${gf}.coordinates`, depth);
      });
    });
  }

  nested(v, field, depth) {
    if (!depth) return this.position(v, field);
    return this.list(v, field, (x, f) => this.nested(x, f, depth - 1));
  }
}

/** ``err`` for the status line: itself when it is skyroute's (an ApiError, a
 * ShapeError among them), else (a page's own fault, or a shape no check caught) a ShapeError
 * saying that ``where``'s answer is not ``what`` as the page reads one, the browser's
 * words kept to the console. */
export function readable(err, where, what) {
  if (err instanceof ApiError) return err;
  console.warn(err);
  return new ShapeError(`the server's answer to ${where} is not ${what} as this page reads one`);
}

/** POST /plan's answer as the planner and world pages show it (a world's waypoints
 * and GeoJSON too, where it gives them). */
export function checkPlan(answer) {
  const a = new Answer("/plan", "a plan");
  a.object(answer);
  a.string(answer.status, "status");
  a.maybe(answer.cost, "cost", a.number);
  a.positions(answer.path, "path");
  for (const k of ["expanded", "seconds"]) a.number(answer[k], k);
  a.maybe(answer.waypoints, "waypoints", (w, f) => a.list(w, f, (p, pf) => {
    if (!Array.isArray(p) || p.length < 4 || !p.every(Number.isFinite)) a.fail(pf, "a waypoint (four numbers)");
  }));
  a.maybe(answer.geojson, "geojson", a.object);
  return answer;
}
