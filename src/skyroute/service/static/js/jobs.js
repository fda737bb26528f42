// Following a long job (POST /jobs/deliver, POST /jobs/fleet) to its end: GET /jobs/{id}
// polled, its share on a <progress> bar (moving without a share while the job gives none:
// a fleet run is one task, 0 until it ends) with the time taken, in an aria-live status
// line. The job is kept in this tab's sessionStorage, so a reload (or a visit to another
// page and back) goes on following it; a server that does not answer is asked again.

import { explain, getJSON, mayPass } from "./api.js";
import { Answer } from "./shape.js";
import { clock, fmt, say, setBusy } from "./ui.js";

const POLL_MS = 500;
export const RETRY_MS = 3000; // between polls while the server does not answer

const pause = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** The id in the answer to a job's POST at ``where`` (``/jobs/fleet``). */
export function jobId(answer, where) {
  const a = new Answer(where, "a job");
  return a.string(a.object(answer).id, "id");
}

/** GET /jobs/{id}'s answer (at ``where``) as it is followed. */
function checkJob(job, where) {
  const a = new Answer(where, "a job");
  a.object(job);
  a.string(job.state, "state");
  a.maybe(job.progress, "progress", a.number);
  a.maybe(job.error, "error", a.string);
  return job;
}

export class JobFollower {
  /**
   * @param {object} parts  key (sessionStorage key of the job followed), bar (progress),
   *   line (status element), button (the submit button, busy while following: it
   *   keeps the focus, see ``setBusy``),
   *   what ("the run": for the messages), done (the text when it is done),
   *   onDone(result) (awaited, after the line says ``done``), hint(error) (optional:
   *   what to do about a failed job's error, said after it; "" for nothing).
   */
  constructor({ key, bar, line, button, what, done, onDone, hint }) {
    Object.assign(this, { key, bar, line, button, what, done, onDone, hint });
  }

  remember(job) {
    try {
      if (job) sessionStorage.setItem(this.key, JSON.stringify(job));
      else sessionStorage.removeItem(this.key);
    } catch {
      // storage refused (private mode): the job is followed until the page goes
    }
  }

  /** The job a page before this one was following ({id, since}), or null. */
  remembered() {
    try {
      const job = JSON.parse(sessionStorage.getItem(this.key) || "null");
      return job && typeof job.id === "string" ? job : null;
    } catch {
      return null;
    }
  }

  /** Follow the job just submitted as ``id``. */
  async start(id) {
    const job = { id, since: Date.now() };
    this.remember(job);
    await this.follow(job);
  }

  /** Poll the job until it is done or failed. */
  async follow({ id, since }) {
    const { bar, line, button, what } = this;
    const took = () => (since ? ` (${clock((Date.now() - since) / 1000)} so far)` : "");
    const following = `Following ${what}`;
    setBusy(button, true);
    try {
      for (;;) {
        let job;
        try {
          // with the token that submitted it: a failed job's error is shown in full
          const where = `/jobs/${encodeURIComponent(id)}`;
          job = checkJob(await getJSON(where, { token: true }), where);
        } catch (err) {
          if (mayPass(err)) { // no answer (or none in time), a 5xx, a proxy's page: for now
            say(line, `${explain(err, following)} Asking again every ${RETRY_MS / 1000} s…`, "error");
            await pause(RETRY_MS);
            continue;
          }
          this.remember(null);
          say(line, explain(err, following), "error");
          return;
        }
        if (job.state === "failed") {
          this.remember(null);
          bar.value = 0;
          const error = job.error || "no reason given";
          const hint = this.hint ? this.hint(job.error) : "";
          const stop = /[.!?]$/.test(error) ? "" : "."; // the hint is a sentence of its own
          say(line, `The job failed: ${error}${hint ? `${stop} ${hint}` : ""}`, "error");
          return;
        }
        if (job.state === "done") {
          this.remember(null);
          bar.value = 1;
          say(line, this.done, "ok");
          if (this.onDone) await this.onDone(job.result || {});
          return;
        }
        const share = job.progress || 0;
        if (job.state === "running" && share > 0) {
          bar.value = share;
          say(line, `Job running: ${fmt(100 * share, 0)} %${took()}`, "busy");
        } else {
          bar.removeAttribute("value"); // indeterminate: moving, no share to show
          say(line, job.state === "queued" ? `Job queued: waiting for a worker${took()}…`
            : `Job running: ${what} reports when it is done${took()}…`, "busy");
        }
        await pause(POLL_MS);
      }
    } finally {
      if (!bar.hasAttribute("value")) bar.value = 0;
      setBusy(button, false);
    }
  }
}
