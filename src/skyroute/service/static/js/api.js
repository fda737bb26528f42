// Talking to the skyroute service: JSON and text reads, authorised writes (POST and
// DELETE), the bearer token (kept in this tab's sessionStorage, never in a cookie or the
// URL), and errors (application/problem+json) turned into one sentence for the status
// line. Every request has a time limit: a server (or a proxy) that takes the connection
// and never answers is an error the page can say and retry, not a spinner for ever.

const TOKEN_KEY = "skyroute.token";

/** How long an answer may take to begin: past the store's busy timeout (30 s, the
 * server's BUSY_SECONDS), so that a locked store's 503 is what the page says. */
export const WAIT_MS = 45_000;
/** How long POST /plan may take to answer: a search on a large raster took 6.4 s on
 * the FCND city (A* at 0.5 m cells), more on a loaded machine. */
export const PLAN_WAIT_MS = 120_000;
/** How long an answer's body may stop coming (a big tracks.csv on a slow network is
 * slow, not stalled: each piece that arrives starts this again). */
export const IDLE_MS = 20_000;

/** An answer other than 2xx: its status, the problem's detail and field. Status 0: no
 * answer (refused, broken off, or none within the time limit). */
export class ApiError extends Error {
  constructor(status, detail, field = null) {
    super(detail);
    this.status = status;
    this.detail = detail;
    this.field = field;
  }
}

function seconds(ms) {
  return ms >= 120_000 && ms % 60_000 === 0 ? `${ms / 60_000} min` : `${ms / 1000} s`;
}

/** The start of ``text`` in one line, for a message about an answer that is not JSON. */
function opening(text) {
  const line = text.replace(/\s+/g, " ").trim();
  return line.length > 40 ? `${line.slice(0, 40)}…` : line;
}

function failure(response, text) {
  // a body that is no problem document (a proxy's HTML page, none at all) gives the
  // status's reason: "502 Bad Gateway", not "(502): 502 Bad Gateway"
  let detail = response.statusText || "no reason given";
  let field = null;
  try {
    const doc = JSON.parse(text);
    if (doc && typeof doc.detail === "string") detail = doc.detail;
    if (doc && typeof doc.field === "string") field = doc.field;
  } catch {
    // not JSON: keep the status's reason
  }
  return new ApiError(response.status, detail, field);
}

/** The URL of the API's ``path`` (``/days``): under the folder of the page, the
 * server's root, so the viewer works behind a proxy that serves it under a path
 * (``skyroute serve --root-path``). A full URL (a ``Link`` the server gave) is kept. */
export function apiURL(path) {
  return path.startsWith("/") ? new URL(`.${path}`, document.baseURI).href : path;
}

/** ``response``'s body as text, ``arm()`` called on each piece that arrives. */
async function readText(response, arm) {
  if (!response.body) return "";
  const reader = response.body.getReader();
  const decoder = new TextDecoder();
  let text = "";
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    arm();
    text += decoder.decode(value, { stream: true });
  }
  return text + decoder.decode();
}

/** Ask for ``path``; ``{response, text}`` once the whole body is in. The answer must
 * begin within ``wait`` ms and its body never stop for ``IDLE_MS``: past either the
 * request is aborted and an ApiError of status 0 says which. */
async function send(path, init, { wait = WAIT_MS } = {}) {
  const control = new AbortController();
  let timer = null;
  const arm = (ms) => {
    clearTimeout(timer);
    timer = setTimeout(() => control.abort(), ms);
  };
  arm(wait);
  try {
    let response;
    try {
      response = await fetch(apiURL(path), { ...init, signal: control.signal });
    } catch {
      throw new ApiError(0, control.signal.aborted ? `the server did not answer within ${seconds(wait)}`
        : "the server did not answer (is skyroute serve still running?)");
    }
    arm(IDLE_MS);
    let text;
    try {
      text = await readText(response, () => arm(IDLE_MS));
    } catch {
      throw new ApiError(0, control.signal.aborted ? `the server's answer stopped coming for ${seconds(IDLE_MS)}`
        : "the server's answer broke off");
    }
    if (!response.ok) throw failure(response, text);
    return { response, text };
  } finally {
    clearTimeout(timer);
  }
}

/** ``text`` as JSON; an ApiError of ``response``'s status if it is none (a proxy's
 * login page, an answer cut short). */
function parsed(response, text) {
  try {
    return JSON.parse(text);
  } catch {
    throw new ApiError(response.status, text.trim() ? `the server's answer is not JSON (it begins "${opening(text)}")`
      : "the server's answer is empty");
  }
}

/** GET ``path``'s JSON; with ``token``, the bearer token too (GET /jobs/{id} shows a
 * failed job's error in full only to the token's holder); ``wait`` as :func:`send`'s. */
export async function getJSON(path, { token = false, wait = WAIT_MS } = {}) {
  const headers = { Accept: "application/json" };
  const { response, text } = await send(path, { headers: token ? authorised(headers) : headers }, { wait });
  return parsed(response, text);
}

/** A page of a paged list: ``{items, next}``, ``next`` the URL of the following page
 * (the answer's ``Link: <...>; rel="next"``, which has the server's root path in it:
 * made full here, not put under the root again) or null on the last page. */
export async function getPage(path) {
  const { response, text } = await send(path, { headers: { Accept: "application/json" } });
  const link = response.headers.get("Link") || "";
  const next = /<([^>]*)>\s*;\s*rel="?next"?/.exec(link);
  return { items: parsed(response, text), next: next ? new URL(next[1], response.url).href : null };
}

export async function getText(path) {
  return (await send(path, {})).text;
}

function authorised(headers) {
  const token = getToken();
  return token ? { ...headers, Authorization: `Bearer ${token}` } : headers;
}

/** POST a JSON body with the bearer token; the answer's JSON. ``wait``: the ms the
 * answer may take to begin (WAIT_MS). */
export async function postJSON(path, body, { wait = WAIT_MS } = {}) {
  const headers = authorised({ "Content-Type": "application/json", Accept: "application/json" });
  const { response, text } = await send(path, { method: "POST", headers, body: JSON.stringify(body) }, { wait });
  return parsed(response, text);
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

/** ``text`` ended as a sentence. */
export function sentence(text) {
  return /[.!?]$/.test(text) ? text : `${text}.`;
}

/** One sentence for the user about ``err`` (an ApiError or anything thrown). Anything
 * else thrown (a TypeError: the page's own fault, or an answer whose shape no check
 * caught) is said in skyroute's words, the browser's kept to the console. */
export function explain(err, what = "the request") {
  if (!(err instanceof ApiError)) {
    console.warn(err);
    return `${what} failed: the page could not read the server's answer.`;
  }
  if (err.status === 401) {
    return `${what} needs the server's token: paste it into the Token field ` +
      "(skyroute serve prints it when it starts, or reads SKYROUTE_TOKEN).";
  }
  if (err.status === 403) return `the server refused the token (403): check the Token field.`;
  // no answer, or a 2xx that is not JSON: no status worth saying
  if (err.status === 0 || err.status < 300) return sentence(`${what} failed: ${err.detail}`);
  return `${what} failed (${err.status}): ${err.detail}`;
}

/** Whether asking again may succeed where ``err`` failed: no answer, a server's fault
 * (5xx), a 408 or a 429, or an answer that was not JSON; not a 4xx that says what is wrong
 * with the request (a day or run not stored, a bad token). */
export function mayPass(err) {
  if (!(err instanceof ApiError)) return true;
  const s = err.status;
  return s === 0 || s < 400 || s >= 500 || s === 408 || s === 429;
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
const SPEC_WAIT_MS = 10_000; // the pages have their own lists: not worth a long wait

/** The choices the server's OpenAPI schema lists for ``schema.property`` (so the pages
 * offer what this server accepts); ``fallback`` when the schema cannot be read. */
export async function choices(schema, property, fallback) {
  try {
    spec = spec || (await getJSON("/openapi.json", { wait: SPEC_WAIT_MS }));
    const prop = spec.components.schemas[schema].properties[property];
    for (const s of [prop, ...(prop.anyOf || [])]) if (Array.isArray(s.enum)) return s.enum;
  } catch {
    // an older server or no schema: the pages' own list
  }
  return fallback;
}
