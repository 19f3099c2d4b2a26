// roverlab dashboard: the page: the websocket, the data it brings (window.viz.data) and the
// drive keys. The side panel (panel.js) and the 2D view (view2d.js) are set up on it here; the
// 3D view (view3d.js) reads window.viz. No build step, no dependencies.
"use strict";
(() => {
  const KIND_MAP = 1, KIND_POINTS = 2, KIND_IMAGE = 3, KIND_POSES = 4, KIND_PATH = 5, KIND_MAP_PATCH = 6;
  const $ = (id) => document.getElementById(id);
  const connEl = $("conn"), driveEl = $("drive-state"), noticeEl = $("notice");
  const redraw = window.vizRedraw, requestDraw = redraw.requestDraw;  // redraw.js: draw only on change

  // view: world point (cx, cy) at the canvas centre, `scale` pixels per metre, the screen's
  // x axis pointing along world direction `angle`
  const view = { cx: 0, cy: 0, scale: 50, angle: 0, placed: false, follow: "", rotate: false, mode: "2D" };
  const data = { config: null, configText: "", layers: [], state: null, topics: [], frames: 0,
                 defaults: null };
  Object.defineProperty(data, "map", { get: () => firstLayer("map", "map") });
  Object.defineProperty(data, "scan", { get: () => { const l = firstLayer("laser_scan", "points"); return l && l.length ? l[l.length - 1] : null; } });
  const configHooks = [];

  function firstLayer(kind, field) {
    if (!data.config) return null;
    for (let i = 0; i < data.config.displays.length; i++) {
      const d = data.config.displays[i], l = data.layers[i];
      if (d.kind === kind && d.enabled && l && l[field]) return l[field];
    }
    return null;
  }
  function layer(slot) { return data.layers[slot] || (data.layers[slot] = {}); }
  // a points display's scans older than its Decay Time go (never the newest); while some are
  // left, a frame when the oldest expires. Both views call it before drawing L.points.
  function expirePoints(d, L) {
    const now = performance.now(), decay = (d.options.decay_s || 0) * 1000;
    if (decay > 0) L.points = L.points.filter((p, i) => i === L.points.length - 1 || now - p.t < decay);
    if (decay > 0 && L.points.length > 1) redraw.requestDrawAt(L.points[0].t + decay);  // it fades
  }

  // ------------------------------------------------------------------ socket
  // the page's ?token= (a dashboard off loopback asks for it on /ws, /config and /mesh/N),
  // added to a request of the server's; displays3d.js fetches meshes through viz.withToken
  const token = new URLSearchParams(location.search).get("token");
  const withToken = (path) => (token ? path + "?token=" + encodeURIComponent(token) : path);
  $("download-config").href = withToken("config");
  const wsUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + withToken("/ws");
  let ws = null, retries = 0, retryTimer = null;
  const conn = { connected: false, attempts: 0 };
  function send(obj) { if (ws && ws.readyState === 1) ws.send(JSON.stringify(obj)); }
  function setConn(text, cls) { connEl.textContent = text; connEl.className = cls; }
  function connect() {
    retryTimer = null;
    conn.attempts += 1;
    ws = new WebSocket(wsUrl);
    ws.binaryType = "arraybuffer";
    ws.onopen = () => { retries = 0; conn.connected = true; setConn("connected", "ok"); };
    ws.onclose = () => {
      conn.connected = false;
      // exponential backoff: 0.5 s, 1 s, 2 s, ... up to 10 s
      const delay = Math.min(10000, 500 * 2 ** retries);
      retries += 1;
      setConn(`disconnected: reconnecting in ${(delay / 1000).toFixed(1)} s (attempt ${retries})`, "bad");
      retryTimer = setTimeout(connect, delay);
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data === "string") onText(JSON.parse(ev.data));
      else onBinary(ev.data);
    };
  }

  // ----------------------------------------------------------------- palettes
  function makePalettes() {
    const map = new Uint32Array(256), costmap = new Uint32Array(256), raw = new Uint32Array(256);
    const pack = (r, g2, b, a) => ((a << 24) | (b << 16) | (g2 << 8) | r) >>> 0;  // little-endian RGBA
    for (let i = 0; i < 256; i++) {
      const v = i > 127 ? i - 256 : i;  // the int8 cell value
      // map: 0 free (light) .. 100 occupied (black), -1 unknown (grey-green), others tinted
      if (v === -1) map[i] = pack(0x70, 0x89, 0x86, 255);
      else if (v >= 0 && v <= 100) { const s = Math.round(255 - v * 255 / 100); map[i] = pack(s, s, s, 255); }
      else if (v > 100) map[i] = pack(0, Math.round(255 * (v - 101) / 26), 0, 255);
      else map[i] = pack(Math.round(255 * (v + 128) / 126), 255, 0, 255);
      // costmap: 0 transparent, 1..98 blue -> red, 99 cyan (inscribed), 100 purple (lethal),
      // -1 unknown (faint grey-green)
      if (v === 0) costmap[i] = pack(0, 0, 0, 0);
      else if (v >= 1 && v <= 98) { const t = v / 98; costmap[i] = pack(Math.round(255 * t), 0, Math.round(255 * (1 - t)), 255); }
      else if (v === 99) costmap[i] = pack(0, 255, 255, 255);
      else if (v === 100) costmap[i] = pack(255, 0, 255, 255);
      else if (v === -1) costmap[i] = pack(0x70, 0x89, 0x86, 60);
      else costmap[i] = pack(0, 255, 0, 255);
      raw[i] = pack(i, i, i, 255);
    }
    return { map, costmap, raw };
  }
  const PALETTES = makePalettes();

  function paintMap(m, scheme, x0, y0, w, h) {
    // rows of the grid go up; the offscreen image's rows go down: flip
    const pal = PALETTES[scheme] || PALETTES.map;
    const img = m.ctx.createImageData(w, h);
    const out = new Uint32Array(img.data.buffer);
    const cells = m.cells, W = m.w;
    for (let r = 0; r < h; r++) {
      const src = (y0 + r) * W + x0, dst = (h - 1 - r) * w;
      for (let c = 0; c < w; c++) out[dst + c] = pal[cells[src + c] & 0xff];
    }
    m.ctx.putImageData(img, x0, m.h - y0 - h);
    m.scheme = scheme;
  }

  function onBinary(buf) {
    const dv = new DataView(buf);
    const kind = dv.getUint8(0), flags = dv.getUint8(1), slot = dv.getUint16(2, true);
    const L = layer(slot);
    const cfg = data.config && data.config.displays[slot];
    if (kind === KIND_MAP) {
      const w = dv.getUint32(4, true), h = dv.getUint32(8, true);
      const res = dv.getFloat32(12, true);
      const ox = dv.getFloat32(16, true), oy = dv.getFloat32(20, true), oyaw = dv.getFloat32(24, true);
      const cells = new Int8Array(buf.slice(28, 28 + w * h));
      const off = document.createElement("canvas");
      off.width = w; off.height = h;
      L.map = { w, h, res, ox, oy, oyaw, cells, canvas: off, ctx: off.getContext("2d") };
      paintMap(L.map, cfg ? cfg.options.color_scheme : "map", 0, 0, w, h);
      L.map.version = 1; L.map.dirty = null;
      if (!view.placed && !(data.state && (data.state.frames.base_footprint || data.state.frames.base_link))) {
        view.cx = ox + w * res / 2; view.cy = oy + h * res / 2;
      }
    } else if (kind === KIND_MAP_PATCH) {
      const m = L.map;
      if (!m) return;
      const x0 = dv.getUint32(4, true), y0 = dv.getUint32(8, true);
      const w = dv.getUint32(12, true), h = dv.getUint32(16, true);
      const patch = new Int8Array(buf, 20, w * h);
      for (let r = 0; r < h; r++) m.cells.set(patch.subarray(r * w, (r + 1) * w), (y0 + r) * m.w + x0);
      paintMap(m, m.scheme, x0, y0, w, h);
      m.version = (m.version || 0) + 1;
      m.dirty = m.dirty ? [Math.min(m.dirty[0], x0), Math.min(m.dirty[1], y0), Math.max(m.dirty[2], x0 + w), Math.max(m.dirty[3], y0 + h)] : [x0, y0, x0 + w, y0 + h];
      const d3 = m.dirty3;  // the same for the 3D view's map levels (it clears its own)
      m.dirty3 = d3 ? [Math.min(d3[0], x0), Math.min(d3[1], y0), Math.max(d3[2], x0 + w), Math.max(d3[3], y0 + h)] : [x0, y0, x0 + w, y0 + h];
    } else if (kind === KIND_POINTS) {
      // flags: 1 = (x, y, z) triples, 2 = one RGBA colour per point after the points
      const n = dv.getUint32(4, true), nb = dv.getUint32(8, true);
      const stride = flags & 1 ? 3 : 2;
      const counts = new Uint32Array(buf, 12, nb);
      const colours = new Uint8Array(buf, 12 + 4 * nb, 4 * nb);
      const pts = new Float32Array(buf, 12 + 8 * nb, n * stride);
      let rgba;
      if (flags & 2) rgba = new Uint8Array(buf, 12 + 8 * nb + 4 * n * stride, 4 * n);
      else {
        rgba = new Uint8Array(4 * n);
        let k = 0;
        for (let b = 0; b < nb; b++) {
          for (let j = 0; j < counts[b]; j++, k++) rgba.set(colours.subarray(4 * b, 4 * b + 4), 4 * k);
        }
      }
      const buckets = [];
      let at = 0;
      if (!(flags & 2)) {
        for (let b = 0; b < nb; b++) {
          if (counts[b]) buckets.push({ color: `rgba(${colours[4 * b]},${colours[4 * b + 1]},${colours[4 * b + 2]},${colours[4 * b + 3] / 255})`,
                                        pts: pts.subarray(at * stride, (at + counts[b]) * stride) });
          at += counts[b];
        }
      }
      const scan = { t: performance.now(), n, buckets, length: n * 2, stride, xyz: pts, rgba, perPoint: !!(flags & 2) };
      const decay = cfg ? (cfg.options.decay_s || 0) : 0;
      const keep = (L.points || []).filter((p) => decay > 0 && scan.t - p.t < decay * 1000);
      keep.push(scan);
      L.points = keep;
      L.version = (L.version || 0) + 1;
    } else if (kind === KIND_POSES) {
      // flag 1: full poses (x, y, z, qx, qy, qz, qw) for the 3D view; the top view's yaw
      const n = dv.getUint32(4, true);
      if (flags & 1) {
        const p7 = new Float32Array(buf, 8, n * 7), p3 = new Float32Array(n * 3);
        for (let i = 0; i < n; i++) {
          const x = p7[7 * i + 3], y = p7[7 * i + 4], z = p7[7 * i + 5], w = p7[7 * i + 6];
          p3[3 * i] = p7[7 * i]; p3[3 * i + 1] = p7[7 * i + 1];
          p3[3 * i + 2] = Math.atan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z));
        }
        L.poses = p3; L.poses3 = p7;
      } else { L.poses = new Float32Array(buf, 8, n * 3); L.poses3 = null; }
      L.version = (L.version || 0) + 1;
    } else if (kind === KIND_PATH) {
      // flag 1: (x, y, z) points
      const n = dv.getUint32(4, true);
      if (flags & 1) {
        const p3 = new Float32Array(buf, 8, n * 3), p2 = new Float32Array(n * 2);
        for (let i = 0; i < n; i++) { p2[2 * i] = p3[3 * i]; p2[2 * i + 1] = p3[3 * i + 1]; }
        L.path = p2; L.path3 = p3;
      } else { L.path = new Float32Array(buf, 8, n * 2); L.path3 = null; }
      L.version = (L.version || 0) + 1;
    } else if (kind === KIND_IMAGE) {
      const mime = flags === 1 ? "image/png" : "image/jpeg";
      const el = document.querySelector(`img[data-slot="${slot}"]`);
      if (!el) return;
      const old = el.src;
      el.src = URL.createObjectURL(new Blob([new Uint8Array(buf, 4)], { type: mime }));
      el.classList.add("shown");  // the panel's message gives way to the picture
      const msg = el.parentElement.querySelector(".imgmsg");
      if (msg) msg.textContent = "";
      if (old.startsWith("blob:")) URL.revokeObjectURL(old);
      return;  // the image panel, not the view
    }
    requestDraw();
  }

  function onText(msg) {
    if (msg.type === "state") onState(msg);
    else if (msg.type === "config") onConfig(msg.config);
    else if (msg.type === "markers") {
      const l = layer(msg.slot); l.markers = msg.items; l.markers3d = msg.items3d || null; requestDraw();
    }
    else if (msg.type === "notice") {
      noticeEl.textContent = msg.text; noticeEl.className = msg.level === "error" ? "error" : "";
    }
  }

  let drawnState = "";
  function onState(msg) {
    data.state = msg;
    // the server sends the state 10 times a second; a frame only when what is drawn moved
    const key = JSON.stringify([msg.fixed_frame, msg.frames, msg.frames3, msg.robot, msg.robot3d, msg.displays]);
    if (key !== drawnState) { drawnState = key; requestDraw(); }
    const base = msg.frames.base_footprint || msg.frames.base_link;
    if (!view.placed && base) { view.cx = base[0]; view.cy = base[1]; view.placed = true; }
    if (msg.topics) { data.topics = msg.topics; renderTopics(); }
    updateStatus(msg.status);
    updateFrameSelects(msg);
    renderImageTopics(msg.image_topics || []);
    renderJoints(msg.joints || []);
    const sp = $("speed"), tu = $("turn");
    if (document.activeElement !== sp) sp.value = msg.drive.speed.toFixed(3);
    if (document.activeElement !== tu) tu.value = msg.drive.turn.toFixed(3);
  }

  // the side panel (panel.js) and the 2D view (view2d.js), on this page's state
  const { onConfig, renderTopics, updateStatus, updateFrameSelects, renderImageTopics, renderJoints } =
    window.vizPanel({ $, view, data, send, redraw, requestDraw, configHooks, paintMap });
  const { worldToScreen, screenToWorld, setTool, getTool, framePose } =
    window.vizView2d({ $, view, data, send, redraw, requestDraw, expirePoints });

  // ------------------------------------------------------------------ drive
  const DRIVE_KEYS = new Set(["i", "j", "l", ",", "k", "u", "o", "m", ".", "I", "J", "L", "<", "U", "O", "M", ">", "t", "b"]);
  const SPEED_KEYS = new Set(["q", "z", "w", "x", "e", "c"]);
  let held = null;
  function typing(ev) { const t = ev.target.tagName; return t === "INPUT" || t === "SELECT" || t === "TEXTAREA"; }
  function press(key) { held = key; send({ type: "key", key }); driveEl.textContent = "key " + key; }
  function release() { if (held === null) return; held = null; send({ type: "key", key: "k" }); driveEl.textContent = "stopped"; }
  window.addEventListener("keydown", (ev) => {
    if (typing(ev)) return;
    if (SPEED_KEYS.has(ev.key)) { send({ type: "key", key: ev.key }); return; }
    if (!DRIVE_KEYS.has(ev.key) || ev.repeat && held === ev.key) return;
    press(ev.key);
  });
  window.addEventListener("keyup", (ev) => { if (ev.key === held) release(); });
  window.addEventListener("blur", release);
  setInterval(() => { if (held) send({ type: "key", key: held }); }, 100);  // keep-alive
  for (const b of document.querySelectorAll("#drive-pad button")) {
    b.addEventListener("mousedown", () => press(b.dataset.key));
    b.addEventListener("mouseup", release);
    b.addEventListener("mouseleave", release);
  }
  function sendSpeeds() {
    const s = Number($("speed").value), t = Number($("turn").value);
    if (Number.isFinite(s) && Number.isFinite(t) && s >= 0 && t >= 0) send({ type: "speed", speed: s, turn: t });
  }
  $("speed").onchange = sendSpeeds; $("turn").onchange = sendSpeeds;

  // view: setting a property through it asks for a frame (redraw.watch)
  window.viz = { view: redraw.watch(view), data, conn, worldToScreen, screenToWorld, setTool, send, PALETTES,
                 configHooks, getTool, framePose, redraw, requestDraw, expirePoints, withToken };
  connect();
  requestDraw();
})();
