// dvqp console: the WebSocket client, JOG keys and buttons, status line and render loop.
// Protocol (docs/console.md): the server sends "scene" once, then "state" at >= 30 Hz and
// "error" for a refused message; the page sends "jog" {velocity: [l, z, h, alpha]}, "stop",
// "reset". A JOG is held while a key or button is held, and stopped when the page loses focus.
"use strict";

(function () {
  const token = new URLSearchParams(location.search).get("token") || "";
  const $ = (id) => document.getElementById(id);
  const dv = $("dv"), section = $("section"), heightsCanvas = $("heights");
  const TRAIL = 150, SPAN = 10;  // trail: states (3 s at 50 Hz); heights: seconds
  const KEYS = {
    ArrowRight: "l+1", KeyD: "l+1", ArrowLeft: "l-1", KeyA: "l-1",
    ArrowUp: "z+1", KeyW: "z+1", ArrowDown: "z-1", KeyS: "z-1",
    PageUp: "h+1", KeyR: "h+1", PageDown: "h-1", KeyF: "h-1",
    KeyE: "a+1", KeyQ: "a-1",
  };
  const AXIS = { l: 0, z: 1, h: 2, a: 3 };

  let ws = null, scene = null, state = null, bounds = null, dirty = false, retry = 500;
  let trail = [], history = [], visible = null;
  const held = new Set();
  // Measurements read by tests: states received, key-press-to-drawn-motion latencies (ms).
  const metrics = window.dvqpMetrics = { states: 0, frames: 0, errors: [], latencies: [], pending: null };

  $("save").href = "trajectory.npz?token=" + encodeURIComponent(token);

  function connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    ws = new WebSocket(`${scheme}://${location.host}/ws?token=${encodeURIComponent(token)}`);
    ws.onopen = () => { retry = 500; setConnection(true); };
    ws.onclose = () => {
      setConnection(false); ws = null; releaseAll(false);
      setTimeout(connect, retry); retry = Math.min(5000, retry * 2);
    };
    ws.onmessage = (event) => receive(JSON.parse(event.data));
  }

  function setConnection(ok) {
    const c = $("connection");
    c.textContent = ok ? "connected" : "disconnected: the arm is stopped";
    c.className = ok ? "ok" : "bad";
  }

  function send(message) {
    if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(message));
  }

  function receive(msg) {
    if (msg.type === "scene") {
      scene = msg; bounds = null; visible = null; trail = []; history = [];
      $("scene-name").textContent = `${msg.name} · ${msg.backend} · dt ${msg.dt} s · R ${msg.pipe_radius} m`;
    } else if (msg.type === "state") {
      if (state && msg.t < state.t) { trail = []; history = []; }  // reset
      state = msg; metrics.states += 1; dirty = true;
      updateStatus(msg);
    } else if (msg.type === "error") {
      metrics.errors.push(msg.message);
      note(msg.message, true);
    }
  }

  function fmt(v, digits, unit) {
    return v === null || v === undefined ? "–" : `${v >= 0 ? "+" : ""}${v.toFixed(digits)}${unit}`;
  }

  function updateStatus(s) {
    const tag = $("st-step"), kind = s.status.split(":")[0];
    tag.className = "tag " + kind;
    tag.textContent = kind === "relaxed" ? `relaxed, task error ${s.task_error.toExponential(2)}`
      : kind === "optimal" ? "optimal" : s.status;
    const closest = s.closest ? ` (${s.closest})` : "";
    $("st-clearance").textContent = s.min_clearance === null ? "min clearance – (no obstacle)"
      : `min clearance ${fmt(s.min_clearance * 1000, 1, " mm")}${closest}`;
    $("st-time").textContent = `t ${s.t.toFixed(2)} s`;
    const c = s.command;
    $("st-command").textContent = `command l ${fmt(c[0], 3, "")} z ${fmt(c[1], 3, "")} ` +
      `h ${fmt(c[2], 3, "")} m/s α ${fmt(c[3], 2, "")} rad/s`;
    $("st-rate").textContent = s.realtime === null ? "real time –" : `real time ×${s.realtime.toFixed(2)}`;
    if (s.clamped) note(s.clamped, false);
  }

  let noteTimer = null;
  function note(text, isError) {
    const n = $("st-note");
    n.textContent = text; n.className = isError ? "error" : "";
    clearTimeout(noteTimer);
    noteTimer = setTimeout(() => { n.textContent = ""; }, 4000);
  }

  function speeds() {
    const v = parseFloat($("speed").value);
    return [v, v, v, 10 * v];  // m/s for l, z, h; rad/s for alpha
  }

  function command() {
    const v = [0, 0, 0, 0], s = speeds();
    held.forEach((code) => {
      const i = AXIS[code[0]];
      v[i] += (code[1] === "+" ? 1 : -1) * s[i];
    });
    return v;
  }

  function apply() {
    document.querySelectorAll("[data-jog]").forEach((b) => b.classList.toggle("held", held.has(b.dataset.jog)));
    const v = command();
    if (v.every((x) => x === 0)) { send({ type: "stop" }); return; }
    if (state && !metrics.pending) metrics.pending = { at: performance.now(), tool: state.tool.slice() };
    send({ type: "jog", velocity: v });
  }

  function press(code) { if (!held.has(code)) { held.add(code); apply(); } }
  function release(code) { if (held.delete(code)) apply(); }
  function releaseAll(notify) {
    if (!held.size) return;
    held.clear();
    if (notify) apply();
    else document.querySelectorAll("[data-jog]").forEach((b) => b.classList.remove("held"));
  }

  window.addEventListener("keydown", (e) => {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    const code = KEYS[e.code];
    if (code) { e.preventDefault(); if (!e.repeat) press(code); return; }
    if (e.code === "Space" || e.code === "Escape") { e.preventDefault(); stop(); return; }
    const digit = ["Digit1", "Digit2", "Digit3", "Digit4"].indexOf(e.code);
    if (digit >= 0) { $("speed").selectedIndex = digit; apply(); }
  }, true);
  window.addEventListener("keyup", (e) => { const code = KEYS[e.code]; if (code) { e.preventDefault(); release(code); } }, true);
  window.addEventListener("blur", () => releaseAll(true));
  document.addEventListener("visibilitychange", () => { if (document.hidden) releaseAll(true); });

  document.querySelectorAll("[data-jog]").forEach((b) => {
    b.addEventListener("pointerdown", (e) => { e.preventDefault(); b.setPointerCapture(e.pointerId); press(b.dataset.jog); });
    ["pointerup", "pointercancel", "lostpointercapture"].forEach((t) => b.addEventListener(t, () => release(b.dataset.jog)));
  });
  $("speed").addEventListener("change", () => { if (held.size) apply(); $("speed").blur(); });

  function stop() { held.clear(); apply(); send({ type: "stop" }); }
  $("stop").addEventListener("click", stop);
  $("reset").addEventListener("click", () => { held.clear(); apply(); send({ type: "reset" }); trail = []; history = []; bounds = null; visible = null; });

  function render() {
    requestAnimationFrame(render);
    if (!dirty || !scene || !state) return;
    dirty = false;
    const R = scene.pipe_radius, pts = DvqpDraw.body(state, R), tip = pts[pts.length - 1];
    if (!bounds) bounds = DvqpDraw.initialBounds(scene, pts);
    if (!inView(pts)) pts.forEach((p) => DvqpDraw.include(bounds, p[0], p[1], R));
    trail.push([tip[0], tip[1]]); if (trail.length > TRAIL) trail.shift();
    history.push({ t: state.t, h: pts.map((p) => p[2]) });
    while (history.length && history[0].t < state.t - SPAN) history.shift();
    const drawn = DvqpPanels.developedView(dv, scene, bounds, pts, trail, state);
    const probe = drawn.probe;
    visible = drawn.visible;
    DvqpPanels.crossSection(section, scene, pts);
    DvqpPanels.heights(heightsCanvas, scene, history, SPAN);
    dv.dataset.probe = `${probe[0].toFixed(1)},${probe[1].toFixed(1)}`;
    dv.dataset.tool = state.tool.join(",");
    metrics.frames += 1;
    measure();
  }

  // The body is well inside the drawn developed view (else the view grows to take it in; it
  // does not pan while the body moves inside it).
  function inView(pts) {
    const m = 0.03;
    return visible !== null && pts.every((p) => p[0] > visible.x0 + m && p[0] < visible.x1 - m
      && p[1] > visible.y0 + m && p[1] < visible.y1 - m);
  }

  // Key press to the first frame that draws the probe moved (> 2 µm or 20 µrad: the states
  // carry 1 µm; the first step of a 0.01 m/s JOG ramped over 0.2 s moves it 1.25 µm... 6 µm).
  function measure() {
    const p = metrics.pending;
    if (!p) return;
    const moved = state.tool.some((v, i) => Math.abs(v - p.tool[i]) > (i === 3 ? 2e-5 : 2e-6));
    if (moved) { metrics.latencies.push(performance.now() - p.at); metrics.pending = null; }
    else if (performance.now() - p.at > 2000) metrics.pending = null;
  }

  connect();
  requestAnimationFrame(render);
})();
