// Small DOM helpers shared by the pages: building elements (text only, never HTML from
// data), the aria-live status line, number formats and file downloads.

/** ``h("td", {class: "num"}, "12")``: an element with properties and children. */
export function h(tag, props = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(props || {})) {
    if (v === null || v === undefined || v === false) continue;
    if (k === "class") el.className = v;
    else if (k === "dataset") Object.assign(el.dataset, v);
    else if (k.startsWith("on")) el.addEventListener(k.slice(2), v);
    else if (k in el && typeof v !== "string") el[k] = v;
    else el.setAttribute(k, v === true ? "" : String(v));
  }
  for (const c of children.flat()) {
    if (c === null || c === undefined || c === false) continue;
    el.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return el;
}

/** Mark ``button`` busy (or not): it refuses its action but keeps the focus. A button
 * made ``disabled`` while it has the focus drops the focus to the page's body, and a
 * keyboard or screen reader user is thrown back to the top of the page; so a busy button
 * is ``aria-disabled`` (read as "dimmed", styled as disabled) and the page's handler asks
 * :func:`isBusy` before it acts. */
export function setBusy(button, busy) {
  if (busy) button.setAttribute("aria-disabled", "true");
  else button.removeAttribute("aria-disabled");
}

export function isBusy(button) {
  return button.getAttribute("aria-disabled") === "true";
}

/** Set the status line ``el`` (an aria-live region): kind info, ok, busy or error.
 * With ``retry``, a "Try again" button after the text calls it (what failed to load is
 * asked for again); the next message takes the button away. */
export function say(el, text, kind = "info", { retry = null } = {}) {
  el.dataset.kind = kind;
  el.textContent = text;
  if (!retry) return;
  el.append(" ", h("button", {
    type: "button", class: "retry secondary",
    onclick: () => {
      // the button goes with the next message: the focus stays on the line, not the body
      el.tabIndex = -1;
      el.focus();
      retry();
    },
  }, "Try again"));
}

export function fmt(x, digits = 0) {
  if (x === null || x === undefined || Number.isNaN(x)) return "–";
  return Number(x).toLocaleString("en-GB", { minimumFractionDigits: digits, maximumFractionDigits: digits });
}

export function pounds(pence) {
  return pence === null || pence === undefined ? "–" : `£${(pence / 100).toFixed(2)}`;
}

/** ``seconds`` as m:ss or h:mm:ss. */
export function clock(seconds) {
  const s = Math.max(0, Math.floor(seconds));
  const hh = Math.floor(s / 3600);
  const mm = Math.floor((s % 3600) / 60);
  const ss = String(s % 60).padStart(2, "0");
  return hh ? `${hh}:${String(mm).padStart(2, "0")}:${ss}` : `${mm}:${ss}`;
}

/** Offer ``text`` as a file download called ``name``. */
export function download(name, text, type = "application/json") {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = h("a", { href: url, download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

/** Replace a table body's rows. */
export function fillRows(tbody, rows) {
  tbody.replaceChildren(...rows);
}

/** Distinct colours for paths and drones (colour-blind friendly first eight: Okabe-Ito). */
export const PALETTE = ["#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9",
  "#7a5195", "#000000", "#8c564b", "#bcbd22"];
