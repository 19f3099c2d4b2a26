// roverlab dashboard: when the views draw. A view draws only when something it shows changed
// (requestDraw: a message, the configuration, the camera, a drag, a resize, points expiring,
// a mesh loaded), at most `frameRate` times a second (rviz's Global Options "Frame Rate"),
// on an animation frame. An idle page does not draw at all; rviz renders Frame Rate times a
// second whether anything changed or not.
"use strict";
window.vizRedraw = (() => {
  const r = {
    frameRate: 30,      // the configuration's Frame Rate (frame_rate_hz)
    maxFps: null,       // a page-local cap instead of frameRate (tests, benchmarks; Infinity: none)
    continuous: false,  // draw every animation frame (benchmarks measuring the render speed)
    draw: null,         // the active view's draw function
    draws: 0,           // frames drawn, both views
    dirty: true,
    lastDraw: -Infinity,
  };
  let pending = false, timer = null, timerAt = Infinity;

  function intervalMs() {
    const f = r.maxFps === null || r.maxFps === undefined ? r.frameRate : r.maxFps;
    return f > 0 && Number.isFinite(f) ? 1000 / f : 0;
  }
  function schedule() {
    if (pending) return;
    pending = true;
    // within the Frame Rate's interval since the last frame: wait for it without waking up
    // every animation frame; the frame itself is drawn on an animation frame
    const wait = r.lastDraw + intervalMs() - performance.now();
    if (wait > 20) setTimeout(() => requestAnimationFrame(tick), wait - 12);
    else requestAnimationFrame(tick);
  }
  function tick() {
    pending = false;
    if (!r.dirty && !r.continuous) return;
    const now = performance.now();
    // 3 ms of slack: at 60 Hz a 30 Hz cap draws every second animation frame
    if (now - r.lastDraw < intervalMs() - 3) { schedule(); return; }
    r.dirty = false; r.lastDraw = now; r.draws += 1;
    if (r.draw) r.draw(now);  // may ask for another frame (requestDraw) while it animates
    if (r.continuous) r.requestDraw();
  }
  // something drawn changed: draw it on the next allowed animation frame
  r.requestDraw = () => { r.dirty = true; schedule(); };
  // something drawn changes by itself at time `t` (performance.now() ms): e.g. decaying points
  r.requestDrawAt = (t) => {
    if (t >= timerAt) return;
    if (timer !== null) clearTimeout(timer);
    timerAt = t;
    timer = setTimeout(() => { timer = null; timerAt = Infinity; r.requestDraw(); }, Math.max(0, t - performance.now()));
  };
  // a proxy of `obj` that asks for a frame whenever a property is set through it (window.viz's
  // view and cam: code outside the page that moves the camera gets it drawn)
  r.watch = (obj) => new Proxy(obj, { set(o, k, v) { o[k] = v; r.requestDraw(); return true; } });
  return r;
})();
