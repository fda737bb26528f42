// Talking to the skyroute service: JSON and text reads, authorised writes (POST and
// DELETE), the bearer token (kept in this tab's sessionStorage, never in a cookie or the
// URL), and errors (application/problem+json) turned into one sentence for the status
// line.

const TOKEN_KEY = "skyroute.token";

/** An answer other than 2xx: its status, the problem's detail and field. */
export class ApiError extends Error {
  constructor(status, detail, field = null) {
    super(detail);
    this.status = status;
    this.detail = detail;
    this.field = field;
  }
}

async function failure(response) {
  let detail = `${response.status} ${response.statusText}`.trim();
  let field = null;
  try {
    const doc = await response.json();
    if (doc && typeof doc.detail === "string") detail = doc.detail;
    if (doc && typeof doc.field === "string") field = doc.field;
  } catch {
    // not JSON: keep the status line
  }
  return new ApiError(response.status, detail, field);
}

/** The URL of the API's ``path`` (``/days``): under the folder of the page, the
 * server's root, so the viewer works behind a proxy that serves it under a path
 * (``skyroute serve --root-path``). A full URL (a ``Link`` the server gave) is kept. */
export function apiURL(path) {
  return path.startsWith("/") ? new URL(`.${path}`, document.baseURI).href : path;
}

async function send(path, init) {
  let response;
  try {
    response = await fetch(apiURL(path), init);
  } catch {
    throw new ApiError(0, "the server did not answer (is skyroute serve still running?)");
  }
  if (!response.ok) throw await failure(response);
  return response;
}

/** GET ``path``'s JSON; with ``token``, the bearer token too (GET /jobs/{id} shows a
 * failed job's error in full only to the token's holder). */
export async function getJSON(path, { token = false } = {}) {
  const headers = { Accept: "application/json" };
  return (await send(path, { headers: token ? authorised(headers) : headers })).json();
}

/** A page of a paged list: ``{items, next}``, ``next`` the URL of the following page
 * (the answer's ``Link: <...>; rel="next"``, which has the server's root path in it:
 * made full here, not put under the root again) or null on the last page. */
export async function getPage(path) {
  const response = await send(path, { headers: { Accept: "application/json" } });
  const link = response.headers.get("Link") || "";
  const next = /<([^>]*)>\s*;\s*rel="?next"?/.exec(link);
  return { items: await response.json(), next: next ? new URL(next[1], response.url).href : null };
}

export async function getText(path) {
  return (await send(path, {})).text();
}

function authorised(headers) {
  const token = getToken();
  return token ? { ...headers, Authorization: `Bearer ${token}` } : headers;
}

/** POST a JSON body with the bearer token; the answer's JSON. */
export async function postJSON(path, body) {
  const headers = authorised({ "Content-Type": "application/json", Accept: "application/json" });
  return (await send(path, { method: "POST", headers, body: JSON.stringify(body) })).json();
}

/** DELETE ``path`` with the bearer token (the answer has no body). */
export async function remove(path) {
  await send(path, { method: "DELETE", headers: authorised({ Accept: "application/json" }) });
}

export function getToken() {
  try {
    return (sessionStorage.getItem(TOKEN_KEY) || "").trim();
  } catch {
    return "";
  }
}

/** Keep ``input`` and the stored token in step. */
export function bindToken(input) {
  input.value = getToken();
  input.addEventListener("input", () => {
    try {
      sessionStorage.setItem(TOKEN_KEY, input.value.trim());
    } catch {
      // storage refused (private mode): the field still works for this page
    }
  });
}

/** One sentence for the user about ``err`` (an ApiError or anything thrown). */
export function explain(err, what = "the request") {
  if (!(err instanceof ApiError)) return `${what} failed: ${err && err.message ? err.message : err}`;
  if (err.status === 401) {
    return `${what} needs the server's token: paste it into the Token field ` +
      "(skyroute serve prints it when it starts, or reads SKYROUTE_TOKEN).";
  }
  if (err.status === 403) return `the server refused the token (403): check the Token field.`;
  if (err.status === 0) return `${what} failed: ${err.detail}.`;
  return `${what} failed (${err.status}): ${err.detail}`;
}

/** Move the focus to the control at fault for ``err``: the Token field for a 401 or 403,
 * else the control of the field a 422 names (``err.field``'s first part: `start` of
 * `start[0]`) among ``controls`` ({field: element id}). */
export function focusFault(err, controls = {}) {
  const status = err && err.status;
  const id = status === 401 || status === 403 ? "token"
    : err && typeof err.field === "string" ? controls[err.field.split(/[.[]/)[0]] : undefined;
  const el = id ? document.getElementById(id) : null;
  if (el) el.focus();
}

let spec = null;

/** The choices the server's OpenAPI schema lists for ``schema.property`` (so the pages
 * offer what this server accepts); ``fallback`` when the schema cannot be read. */
export async function choices(schema, property, fallback) {
  try {
    spec = spec || (await getJSON("/openapi.json"));
    const prop = spec.components.schemas[schema].properties[property];
    for (const s of [prop, ...(prop.anyOf || [])]) if (Array.isArray(s.enum)) return s.enum;
  } catch {
    // an older server or no schema: the pages' own list
  }
  return fallback;
}
