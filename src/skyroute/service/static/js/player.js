// Play / pause, speed and a time slider driving an animation: ``onTime(t)`` is called with
// the current time (a float between 0 and the end) on every frame while playing and on
// every move of the slider.

export class Player {
  /**
   * @param {object} parts  play (button), speed (select: units per second), slider
   *   (input range), output (element for the time text), onTime(t), describe(t) -> text.
   */
  constructor({ play, speed, slider, output, onTime, describe, onEnd }) {
    Object.assign(this, { play, speed, slider, output, onTime, describe, onEnd });
    this.t = 0;
    this.end = 0;
    this.playing = false;
    this.last = null;
    play.addEventListener("click", () => (this.playing ? this.pause() : this.start()));
    slider.addEventListener("input", () => this.seek(Number(slider.value)));
    this.frame = this.frame.bind(this);
    this.enable(false);
  }

  enable(on) {
    this.play.disabled = !on;
    this.slider.disabled = !on;
  }

  /** A new animation from 0 to ``end`` (slider steps of ``step``). */
  load(end, step = 1) {
    this.pause();
    this.end = end;
    this.slider.min = "0";
    this.slider.max = String(end);
    this.slider.step = String(step);
    this.enable(end > 0);
    this.seek(0);
  }

  seek(t) {
    this.t = Math.min(Math.max(t, 0), this.end);
    this.show();
  }

  show() {
    if (Number(this.slider.value) !== this.t) this.slider.value = String(this.t);
    const text = this.describe ? this.describe(this.t) : String(this.t);
    this.output.textContent = text;
    this.slider.setAttribute("aria-valuetext", text);
    this.onTime(this.t);
  }

  start() {
    if (this.end <= 0) return;
    if (this.t >= this.end) this.t = 0;
    this.playing = true;
    this.play.textContent = "Pause";
    this.play.setAttribute("aria-pressed", "true");
    this.last = null;
    requestAnimationFrame(this.frame);
  }

  pause() {
    const was = this.playing;
    this.playing = false;
    this.play.textContent = "Play";
    this.play.setAttribute("aria-pressed", "false");
    if (was) this.show(); // whatever is refreshed less often while playing catches up
  }

  frame(now) {
    if (!this.playing) return;
    if (this.last !== null) {
      const dt = Math.min((now - this.last) / 1000, 0.25); // a hidden tab does not jump ahead
      this.t = Math.min(this.t + dt * Number(this.speed.value), this.end);
      this.show();
    }
    this.last = now;
    if (this.t >= this.end) {
      this.pause();
      if (this.onEnd) this.onEnd();
      return;
    }
    requestAnimationFrame(this.frame);
  }
}
