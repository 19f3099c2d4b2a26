// roverlab dashboard: a top-down rviz on one canvas. No build step, no dependencies.
"use strict";
(() => {
  const KIND_MAP = 1, KIND_POINTS = 2, KIND_IMAGE = 3, KIND_POSES = 4, KIND_PATH = 5, KIND_MAP_PATCH = 6;
  const $ = (id) => document.getElementById(id);
  const canvas = $("view");
  const g = canvas.getContext("2d");
  const connEl = $("conn"), driveEl = $("drive-state"), noticeEl = $("notice");
  const redraw = window.vizRedraw, requestDraw = redraw.requestDraw;  // redraw.js: draw only on change

  // Option widgets: choices, and which options are colours.
  const CHOICES = {
    color_scheme: ["map", "costmap", "raw"],
    color_map: ["gray", "jet", "hot", "rainbow"],
    color_transformer: ["FlatColor", "Intensity", "AxisColor", "RGB8"],
    axis: ["X", "Y", "Z"],
  };
  const KIND_TYPES = {
    map: ["nav_msgs/msg/OccupancyGrid"], laser_scan: ["sensor_msgs/msg/LaserScan"],
    robot_model: ["std_msgs/msg/String"], odometry: ["nav_msgs/msg/Odometry"],
    path: ["nav_msgs/msg/Path"], pose_array: ["geometry_msgs/msg/PoseArray"],
    point_cloud2: ["sensor_msgs/msg/PointCloud2"], marker: ["visualization_msgs/msg/Marker"],
    marker_array: ["visualization_msgs/msg/MarkerArray"], pose: ["geometry_msgs/msg/PoseStamped"],
    pose_with_covariance: ["geometry_msgs/msg/PoseWithCovarianceStamped"],
    polygon: ["geometry_msgs/msg/PolygonStamped"],
    image: ["sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"], grid: [], tf: [],
  };
  const KIND_LABEL = {
    grid: "Grid", map: "Map", laser_scan: "LaserScan", robot_model: "RobotModel", tf: "TF",
    odometry: "Odometry", path: "Path", pose_array: "PoseArray", point_cloud2: "PointCloud2",
    marker: "Marker", marker_array: "MarkerArray", pose: "Pose",
    pose_with_covariance: "PoseWithCovariance", polygon: "Polygon", image: "Image",
  };

  // view: world point (cx, cy) at the canvas centre, `scale` pixels per metre, the screen's
  // x axis pointing along world direction `angle`
  const view = { cx: 0, cy: 0, scale: 50, angle: 0, placed: false, follow: "", rotate: false, mode: "2D" };
  const data = { config: null, configText: "", layers: [], state: null, topics: [], frames: 0,
                 defaults: null };
  Object.defineProperty(data, "map", { get: () => firstLayer("map", "map") });
  Object.defineProperty(data, "scan", { get: () => { const l = firstLayer("laser_scan", "points"); return l && l.length ? l[l.length - 1] : null; } });
  let tool = "move";
  let drag = null;

  function firstLayer(kind, field) {
    if (!data.config) return null;
    for (let i = 0; i < data.config.displays.length; i++) {
      const d = data.config.displays[i], l = data.layers[i];
      if (d.kind === kind && d.enabled && l && l[field]) return l[field];
    }
    return null;
  }
  function layer(slot) { return data.layers[slot] || (data.layers[slot] = {}); }

  function worldToScreen(x, y) {
    const dx = x - view.cx, dy = y - view.cy, c = Math.cos(view.angle), s = Math.sin(view.angle);
    return [canvas.width / 2 + (c * dx + s * dy) * view.scale,
            canvas.height / 2 - (-s * dx + c * dy) * view.scale];
  }
  function screenToWorld(px, py) {
    const rx = (px - canvas.width / 2) / view.scale, ry = -(py - canvas.height / 2) / view.scale;
    const c = Math.cos(view.angle), s = Math.sin(view.angle);
    return [view.cx + c * rx - s * ry, view.cy + s * rx + c * ry];
  }
  function worldTransform() {
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.translate(canvas.width / 2, canvas.height / 2);
    g.scale(view.scale, -view.scale);
    g.rotate(-view.angle);
    g.translate(-view.cx, -view.cy);
  }
  const px = (n) => n / view.scale;  // n screen pixels in metres
  const rgba = (c, a) => `rgba(${c[0]},${c[1]},${c[2]},${a})`;
  const rgbaF = (c, alpha) => `rgba(${Math.round(c[0] * 255)},${Math.round(c[1] * 255)},${Math.round(c[2] * 255)},${c[3] * alpha})`;

  // ------------------------------------------------------------------ socket
  const token = new URLSearchParams(location.search).get("token");
  const q = token ? "?token=" + encodeURIComponent(token) : "";
  $("download-config").href = "config" + q;
  const wsUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws" + q;
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

  // joint_state_publisher_gui: one slider per movable joint of the robot description
  function renderJoints(joints) {
    const box = $("joints");
    $("joints-panel").style.display = joints.length ? "" : "none";
    const names = joints.map((j) => j.name).join(",");
    if (box.dataset.names !== names) {
      box.dataset.names = names; box.innerHTML = "";
      for (const j of joints) {
        const row = document.createElement("div"); row.className = "row";
        const label = document.createElement("span"); label.textContent = j.name; label.style.width = "40%";
        const inp = document.createElement("input"); inp.type = "range"; inp.className = "joint";
        inp.min = j.lower; inp.max = j.upper; inp.step = (j.upper - j.lower) / 1000; inp.dataset.joint = j.name;
        const val = document.createElement("span"); val.className = "joint-value";
        inp.oninput = () => { val.textContent = Number(inp.value).toFixed(2); send({ type: "joint", name: j.name, position: Number(inp.value) }); };
        row.append(label, inp, val); box.append(row);
      }
    }
    for (const j of joints) {
      const inp = box.querySelector(`input[data-joint="${CSS.escape(j.name)}"]`);
      if (inp && document.activeElement !== inp) { inp.value = j.position; inp.nextSibling.textContent = j.position.toFixed(2); }
    }
  }

  // -------------------------------------------------------------- side panel
  function sendConfig() {
    data.configText = JSON.stringify(data.config);
    send({ type: "config", config: data.config });
    applyFrameRate();
    requestDraw();
  }
  // rviz's Global Options Frame Rate: the most frames a second either view draws
  function applyFrameRate() {
    const rate = data.config && data.config.frame_rate_hz;
    redraw.frameRate = rate >= 1 ? rate : 30;
    const inp = $("frame-rate");
    if (document.activeElement !== inp) inp.value = redraw.frameRate;
  }
  $("frame-rate").onchange = () => {
    const v = Number($("frame-rate").value);
    if (data.config && Number.isFinite(v) && v >= 1) { data.config.frame_rate_hz = v; sendConfig(); } else applyFrameRate();
  };

  function onConfig(config) {
    const text = JSON.stringify(config);
    if (text === data.configText) return;  // our own change coming back
    const old = data.config;
    data.config = config; data.configText = text;
    if (!data.defaults) data.defaults = {};
    // layers follow their display: drop the data of displays whose kind/topic changed
    const layers = [];
    config.displays.forEach((d, i) => {
      const o = old && old.displays[i];
      if (o && o.kind === d.kind && o.topic === d.topic && data.layers[i]) layers[i] = data.layers[i];
    });
    data.layers = layers;
    for (const hook of configHooks) hook(config, old);
    renderDisplays();
    renderImages();
    applyFrameRate();
    requestDraw();
  }

  function colourHex(c) { return "#" + c.map((v) => v.toString(16).padStart(2, "0")).join(""); }
  function hexColour(h) { return [1, 3, 5].map((i) => parseInt(h.substr(i, 2), 16)); }

  function topicChoices(kind) {
    const types = KIND_TYPES[kind] || [];
    return data.topics.filter((t) => types.includes(t.type)).map((t) => t.name);
  }

  function propRow(label, input) {
    const row = document.createElement("div"); row.className = "prop";
    const s = document.createElement("span"); s.textContent = label;
    row.append(s, input);
    return row;
  }

  function renderDisplays() {
    const box = $("displays");
    const open = new Set(Array.from(box.querySelectorAll(".display.open")).map((e) => e.dataset.slot));
    box.innerHTML = "";
    data.config.displays.forEach((d, slot) => {
      const el = document.createElement("div");
      el.className = "display" + (open.has(String(slot)) ? " open" : "");
      el.dataset.slot = slot; el.dataset.kind = d.kind;
      const head = document.createElement("div"); head.className = "dhead";
      const cb = document.createElement("input"); cb.type = "checkbox"; cb.checked = d.enabled;
      cb.className = "enabled";
      cb.onclick = (ev) => ev.stopPropagation();
      cb.onchange = () => { d.enabled = cb.checked; sendConfig(); renderImages(); };
      const dot = document.createElement("span"); dot.className = "dot";
      const name = document.createElement("span"); name.className = "dname";
      name.textContent = d.name + "  (" + (KIND_LABEL[d.kind] || d.kind) + ")";
      head.append(cb, dot, name);
      head.onclick = () => el.classList.toggle("open");
      const body = document.createElement("div"); body.className = "dbody";
      if ((KIND_TYPES[d.kind] || []).length || d.kind === "robot_model") {
        const inp = document.createElement("input"); inp.value = d.topic; inp.className = "topic";
        const listId = "topics-" + slot;
        inp.setAttribute("list", listId);
        const dl = document.createElement("datalist"); dl.id = listId;
        inp.onfocus = () => { dl.innerHTML = ""; for (const t of topicChoices(d.kind)) { const o = document.createElement("option"); o.value = t; dl.appendChild(o); } };
        inp.onchange = () => { d.topic = inp.value.trim(); sendConfig(); renderImages(); };
        body.append(propRow(d.kind === "robot_model" ? "Description topic" : "Topic", inp), dl);
      }
      for (const [key, value] of Object.entries(d.options)) {
        let inp;
        if (CHOICES[key]) {
          inp = document.createElement("select");
          for (const c of CHOICES[key]) { const o = document.createElement("option"); o.value = o.textContent = c; inp.appendChild(o); }
          inp.value = value;
          inp.onchange = () => { d.options[key] = inp.value; sendConfig(); onOptionChanged(slot, key); };
        } else if (typeof value === "boolean") {
          inp = document.createElement("input"); inp.type = "checkbox"; inp.checked = value;
          inp.onchange = () => { d.options[key] = inp.checked; sendConfig(); };
        } else if (Array.isArray(value)) {
          inp = document.createElement("input"); inp.type = "color"; inp.value = colourHex(value);
          inp.onchange = () => { d.options[key] = hexColour(inp.value); sendConfig(); };
        } else if (typeof value === "number") {
          inp = document.createElement("input"); inp.type = "number"; inp.value = value;
          inp.step = key === "alpha" ? "0.1" : (Number.isInteger(value) && !/size|length|width|decay|tolerance|scale|value/.test(key) ? "1" : "0.05");
          if (key === "alpha") { inp.min = "0"; inp.max = "1"; }
          inp.onchange = () => {
            const v = Number(inp.value);
            if (!Number.isFinite(v)) return;
            d.options[key] = inp.step === "1" ? Math.round(v) : v; sendConfig();
          };
        } else {
          inp = document.createElement("input"); inp.value = value;
          inp.onchange = () => { d.options[key] = inp.value; sendConfig(); };
        }
        inp.dataset.option = key;
        body.append(propRow(key.replace(/_/g, " "), inp));
      }
      const nm = document.createElement("input"); nm.value = d.name;
      nm.onchange = () => { d.name = nm.value; sendConfig(); renderDisplays(); renderImages(); };
      body.append(propRow("name", nm));
      const rm = document.createElement("button"); rm.textContent = "Remove";
      rm.onclick = () => { data.config.displays.splice(slot, 1); data.layers.splice(slot, 1); sendConfig(); renderDisplays(); renderImages(); };
      body.append(rm);
      const st = document.createElement("div"); st.className = "status";
      body.append(st);
      el.append(head, body);
      box.appendChild(el);
    });
    const add = $("add-kind");
    if (!add.options.length) for (const k of Object.keys(KIND_LABEL)) { const o = document.createElement("option"); o.value = k; o.textContent = KIND_LABEL[k]; add.appendChild(o); }
    if (data.state) updateStatus(data.state.status);
  }

  function onOptionChanged(slot, key) {
    const L = data.layers[slot], d = data.config.displays[slot];
    if (key === "color_scheme" && L && L.map) paintMap(L.map, d.options.color_scheme, 0, 0, L.map.w, L.map.h);
  }

  const POINT_COLOURS = {  // rviz's Intensity and AxisColor transformers (defaults as rviz)
    channel_name: "intensity", autocompute_intensity_bounds: true, min_intensity: 0.0, max_intensity: 4096.0,
    use_rainbow: true, invert_rainbow: false, min_color: [0, 0, 0], max_color: [255, 255, 255],
    axis: "Z", autocompute_value_bounds: true, min_value: -10.0, max_value: 10.0, use_fixed_frame: true,
  };
  const DEFAULT_OPTIONS = {
    grid: { cell_size: 1.0, cell_count: 10, color: [160, 160, 164], alpha: 0.5, reference_frame: "" },
    map: { alpha: 0.7, color_scheme: "map", draw_behind: false },
    laser_scan: { color: [255, 0, 0], color_transformer: "FlatColor", size_px: 3.0, alpha: 1.0, decay_s: 0.0, ...POINT_COLOURS },
    robot_model: { alpha: 1.0 }, tf: { show_names: true, show_axes: true, scale: 1.0 },
    odometry: { keep: 100, color: [255, 25, 0], alpha: 1.0, position_tolerance: 0.1, angle_tolerance: 0.1, length: 1.3 },
    path: { color: [25, 255, 0], alpha: 1.0, line_width: 0.03 },
    pose_array: { color: [255, 25, 0], alpha: 1.0, length: 0.3 },
    point_cloud2: { color_transformer: "AxisColor", color: [255, 255, 255], size_px: 2.0, alpha: 1.0, max_points: 20000, decay_s: 0.0, ...POINT_COLOURS },
    marker: {}, marker_array: {}, pose: { color: [255, 25, 0], alpha: 1.0, length: 1.3 },
    pose_with_covariance: { color: [255, 25, 0], alpha: 1.0, length: 1.0, covariance_scale: 1.0 },
    polygon: { color: [25, 255, 0], alpha: 1.0 },
    image: { color_map: "jet", min_value: 0.0, max_value: 0.0 },
  };
  const DEFAULT_TOPIC = {
    map: "/map", laser_scan: "/scan", robot_model: "/robot_description", odometry: "/odom",
    path: "/move_base/NavfnROS/plan", pose_array: "/particlecloud", point_cloud2: "/camera/depth/points",
    marker: "/visualization_marker", marker_array: "/visualization_marker_array",
    pose: "/move_base_simple/goal", pose_with_covariance: "/amcl_pose", image: "/image_raw",
    polygon: "/move_base/local_costmap/footprint",
    grid: "", tf: "",
  };
  $("add-display").onclick = () => {
    const k = $("add-kind").value;
    data.config.displays.push({ kind: k, name: KIND_LABEL[k], enabled: true, topic: DEFAULT_TOPIC[k],
                                options: JSON.parse(JSON.stringify(DEFAULT_OPTIONS[k])) });
    sendConfig(); renderDisplays(); renderImages();
  };
  $("save-config").onclick = () => send({ type: "save_config" });
  $("save-map").onclick = () => send({ type: "save_map", name: $("map-name").value.trim() || "map" });

  function worst(rows) {
    const order = { error: 3, warn: 2, ok: 1, disabled: 0 };
    let w = "disabled";
    for (const r of rows) if ((order[r[0]] || 0) > order[w]) w = r[0];
    return w;
  }
  function statusHtml(rows) {
    const div = document.createElement("div");
    for (const [lvl, name, text] of rows) {
      const r = document.createElement("div"); r.className = "srow " + lvl;
      const dot = document.createElement("span"); dot.className = "lvl";
      const n = document.createElement("span"); n.className = "sname"; n.textContent = name + ":";
      const t = document.createElement("span"); t.textContent = text;
      r.append(dot, n, t); div.appendChild(r);
    }
    return div;
  }
  function updateStatus(status) {
    if (!status || !data.config) return;
    const gs = $("global-status"); gs.innerHTML = ""; gs.appendChild(statusHtml(status.global));
    const els = $("displays").querySelectorAll(".display");
    status.displays.forEach((rows, slot) => {
      const el = els[slot];
      if (!el) return;
      el.querySelector(".dot").className = "dot " + worst(rows);
      const st = el.querySelector(".status");
      st.innerHTML = ""; st.appendChild(statusHtml(rows));
      el.dataset.status = worst(rows);
    });
  }

  function fillSelect(sel, values, current, none) {
    const want = (none !== undefined ? [none] : []).concat(values);
    if (!want.includes(current)) want.push(current);
    const have = Array.from(sel.options).map((o) => o.value);
    if (have.join("\n") !== want.join("\n")) {
      sel.innerHTML = "";
      for (const v of want) { const o = document.createElement("option"); o.value = v; o.textContent = v || "(none)"; sel.appendChild(o); }
    }
    if (document.activeElement !== sel) sel.value = current;
  }
  function updateFrameSelects(msg) {
    const frames = Object.keys(msg.frames).sort();
    if (data.config) fillSelect($("fixed-frame"), frames, data.config.fixed_frame);
    fillSelect($("follow"), frames, view.follow, "");
  }
  $("fixed-frame").onchange = () => { data.config.fixed_frame = $("fixed-frame").value; sendConfig(); };
  $("follow").onchange = () => { view.follow = $("follow").value; view.placed = true; requestDraw(); };
  $("rotate-follow").onchange = () => { view.rotate = $("rotate-follow").checked; requestDraw(); };
  $("rot-left").onclick = () => { view.angle -= Math.PI / 12; requestDraw(); };
  $("rot-right").onclick = () => { view.angle += Math.PI / 12; requestDraw(); };
  $("rot-reset").onclick = () => { view.angle = 0; view.rotate = false; $("rotate-follow").checked = false; requestDraw(); };

  // image panels: one per enabled image display, the first with ids image-topic / camera
  function renderImages() {
    const box = $("images");
    box.innerHTML = "";
    if (!data.config) return;
    let first = true;
    data.config.displays.forEach((d, slot) => {
      if (d.kind !== "image" || !d.enabled) return;
      const div = document.createElement("div"); div.className = "imgbox";
      const row = document.createElement("div"); row.className = "row";
      const sel = document.createElement("select"); sel.className = "image-topic"; sel.dataset.slot = slot;
      sel.onchange = () => { d.topic = sel.value; sendConfig(); };
      const cm = document.createElement("select");
      for (const c of CHOICES.color_map) { const o = document.createElement("option"); o.value = o.textContent = c; cm.appendChild(o); }
      cm.value = d.options.color_map; cm.title = "colour map of depth images";
      cm.onchange = () => { d.options.color_map = cm.value; sendConfig(); renderDisplays(); };
      row.append(sel, cm);
      const img = document.createElement("img"); img.dataset.slot = slot; img.alt = d.name;
      if (first) { sel.id = "image-topic"; img.id = "camera"; first = false; }
      div.append(row, img); box.appendChild(div);
    });
    if (first) {  // no image display: a picker that makes one
      const sel = document.createElement("select"); sel.id = "image-topic"; sel.className = "image-topic";
      sel.onchange = () => { if (sel.value) send({ type: "image_topic", topic: sel.value }); };
      const row = document.createElement("div"); row.className = "row"; row.append(sel); box.appendChild(row);
    }
    renderImageTopics(data.state ? data.state.image_topics || [] : []);
  }
  function renderImageTopics(topics) {
    for (const sel of document.querySelectorAll("select.image-topic")) {
      const slot = sel.dataset.slot;
      const current = slot !== undefined ? data.config.displays[slot].topic : "";
      fillSelect(sel, topics, current, slot !== undefined ? undefined : "");
    }
  }

  function renderTopics() {
    const t = $("topics");
    const rows = data.topics.map((x) => {
      const hz = x.hz === null || x.hz === undefined ? "-" : x.hz.toFixed(1);
      return `<tr class="${x.publishers ? "" : "none"}" title="${x.type}: ${x.publishers} publisher(s), ${x.subscribers} subscriber(s)"><td>${x.name}</td><td class="hz">${hz} Hz</td></tr>`;
    });
    t.innerHTML = rows.join("");
  }

  // ---------------------------------------------------------------- drawing
  function framePose(name) {
    const s = data.state;
    if (!s) return null;
    if (!name || name === s.fixed_frame) return [0, 0, 0];
    return s.frames[name] || null;
  }
  function drawGrid(d) {
    const o = d.options, pose = framePose(o.reference_frame);
    if (!pose) return;
    const n = Math.max(1, o.cell_count), size = o.cell_size, half = n * size / 2;
    g.save();
    g.translate(pose[0], pose[1]); g.rotate(pose[2]);
    g.strokeStyle = rgba(o.color, o.alpha); g.lineWidth = px(1);
    g.beginPath();
    for (let i = 0; i <= n; i++) {
      const v = -half + i * size;
      g.moveTo(v, -half); g.lineTo(v, half); g.moveTo(-half, v); g.lineTo(half, v);
    }
    g.stroke(); g.restore();
  }
  function drawMap(d, L, info) {
    const m = L.map;
    if (!m) return;
    const fp = framePose(info && info.frame ? info.frame : "map");
    if (!fp) return;
    g.save();
    g.globalAlpha = Math.max(0, Math.min(1, d.options.alpha));
    g.imageSmoothingEnabled = false;
    g.translate(fp[0], fp[1]); g.rotate(fp[2]);
    g.translate(m.ox, m.oy); g.rotate(m.oyaw);
    g.scale(1, -1);  // the offscreen image's first row is the map's top row
    g.drawImage(m.canvas, 0, -m.h * m.res, m.w * m.res, m.h * m.res);
    g.restore();
  }
  function drawPoints(d, L) {
    if (!L.points) return;
    const now = performance.now(), decay = (d.options.decay_s || 0) * 1000;
    if (decay > 0) L.points = L.points.filter((p, i) => i === L.points.length - 1 || now - p.t < decay);
    if (decay > 0 && L.points.length > 1) redraw.requestDrawAt(L.points[0].t + decay);  // it fades
    const h = px(d.options.size_px || 3) / 2, s = 2 * h;
    for (const scan of L.points) {
      const st = scan.stride;
      if (scan.perPoint) {
        const p = scan.xyz, c = scan.rgba;
        for (let i = 0, k = 0; i < p.length; i += st, k += 4) {
          g.fillStyle = `rgba(${c[k]},${c[k + 1]},${c[k + 2]},${c[k + 3] / 255})`;
          g.fillRect(p[i] - h, p[i + 1] - h, s, s);
        }
      }
      for (const b of scan.buckets) {
        g.fillStyle = b.color;
        const p = b.pts;
        for (let i = 0; i < p.length; i += st) g.fillRect(p[i] - h, p[i + 1] - h, s, s);
      }
    }
  }
  function drawRobot(d) {
    const s = data.state;
    if (!s) return;
    for (const part of s.robot) {
      g.fillStyle = rgbaF(part.rgba, d.options.alpha);
      g.beginPath();
      part.points.forEach(([x, y], i) => { if (i) g.lineTo(x, y); else g.moveTo(x, y); });
      g.closePath(); g.fill();
    }
  }
  function arrowWorld(x, y, yaw, len, color, width) {
    // an rviz arrow seen from above: shaft 77 %, head 23 % of the length
    const head = len * 0.23, shaft = len - head, w = Math.max(width, px(2));
    g.save(); g.translate(x, y); g.rotate(yaw);
    g.fillStyle = color;
    g.fillRect(0, -w / 2, shaft, w);
    g.beginPath(); g.moveTo(shaft, -Math.max(w * 2, len * 0.1)); g.lineTo(len, 0);
    g.lineTo(shaft, Math.max(w * 2, len * 0.1)); g.closePath(); g.fill();
    g.restore();
  }
  function drawPoses(d, L, widthFrac) {
    const p = L.poses;
    if (!p) return;
    const color = rgba(d.options.color, d.options.alpha), len = d.options.length;
    for (let i = 0; i < p.length; i += 3) arrowWorld(p[i], p[i + 1], p[i + 2], len, color, len * widthFrac);
  }
  function drawPath(d, L) {
    const p = L.path;
    if (!p || p.length < 4) return;
    g.strokeStyle = rgba(d.options.color, d.options.alpha);
    g.lineWidth = Math.max(d.options.line_width, px(1.5)); g.lineJoin = "round";
    g.beginPath(); g.moveTo(p[0], p[1]);
    for (let i = 2; i < p.length; i += 2) g.lineTo(p[i], p[i + 1]);
    g.stroke();
  }
  function drawTf(d) {
    const s = data.state;
    if (!s) return;
    const len = 0.3 * d.options.scale, o = d.options;
    if (o.show_axes) {
      g.lineWidth = px(2);
      for (const [x, y, yaw] of Object.values(s.frames).concat([[0, 0, 0]])) {
        g.strokeStyle = "rgb(230,40,40)"; g.beginPath(); g.moveTo(x, y);
        g.lineTo(x + Math.cos(yaw) * len, y + Math.sin(yaw) * len); g.stroke();
        g.strokeStyle = "rgb(40,200,40)"; g.beginPath(); g.moveTo(x, y);
        g.lineTo(x - Math.sin(yaw) * len, y + Math.cos(yaw) * len); g.stroke();
      }
    }
    if (o.show_names) {
      g.save(); g.setTransform(1, 0, 0, 1, 0, 0);
      g.fillStyle = "rgba(255,255,255,0.85)"; g.font = "11px sans-serif";
      for (const [name, [x, y]] of Object.entries(s.frames)) {
        const [sx, sy] = worldToScreen(x, y); g.fillText(name, sx + 4, sy - 4);
      }
      g.restore();
    }
  }
  function drawMarkers(L) {
    if (!L.markers) return;
    for (const m of L.markers) {
      const c = rgbaF(m.rgba, 1);
      const pts = m.points;
      if (m.shape === "polygon") {
        g.fillStyle = c; g.beginPath();
        pts.forEach(([x, y], i) => { if (i) g.lineTo(x, y); else g.moveTo(x, y); });
        g.closePath(); g.fill();
      } else if (m.shape === "polyline" || m.shape === "lines") {
        g.lineWidth = Math.max(m.width, px(1));
        if (m.colors || m.shape === "lines") {
          const step = m.shape === "lines" ? 2 : 1;
          for (let i = 0; i + 1 < pts.length; i += step) {
            g.strokeStyle = m.colors ? rgbaF(m.colors[i], 1) : c;
            g.beginPath(); g.moveTo(pts[i][0], pts[i][1]); g.lineTo(pts[i + 1][0], pts[i + 1][1]); g.stroke();
          }
        } else {
          g.strokeStyle = c; g.beginPath();
          pts.forEach(([x, y], i) => { if (i) g.lineTo(x, y); else g.moveTo(x, y); });
          g.stroke();
        }
      } else if (m.shape === "points") {
        const h = Math.max(m.size, px(2)) / 2;
        pts.forEach(([x, y], i) => {
          g.fillStyle = m.colors ? rgbaF(m.colors[i], 1) : c;
          if (m.round) { g.beginPath(); g.arc(x, y, h, 0, 2 * Math.PI); g.fill(); }
          else g.fillRect(x - h, y - h, 2 * h, 2 * h);
        });
      } else if (m.shape === "arrow") {
        arrowWorld(pts[0][0], pts[0][1], m.yaw, m.length, c, m.width);
      } else if (m.shape === "text") {
        g.save(); g.setTransform(1, 0, 0, 1, 0, 0);
        const [sx, sy] = worldToScreen(pts[0][0], pts[0][1]);
        g.fillStyle = c; g.textAlign = "center"; g.textBaseline = "middle";
        g.font = Math.max(8, Math.round(m.height * view.scale)) + "px sans-serif";
        g.fillText(m.text, sx, sy); g.restore();
      }
    }
  }
  function drawDisplay(d, slot) {
    const L = data.layers[slot] || {};
    const info = data.state && data.state.displays ? data.state.displays[slot] : null;
    switch (d.kind) {
      case "grid": drawGrid(d); break;
      case "map": drawMap(d, L, info); break;
      case "laser_scan": case "point_cloud2": drawPoints(d, L); break;
      case "robot_model": drawRobot(d); break;
      case "tf": drawTf(d); break;
      case "odometry": drawPoses(d, L, 0.04); break;
      case "pose": drawPoses(d, L, 0.04); break;
      case "pose_array": drawPoses(d, L, 0.06); break;
      case "path": drawPath(d, L); break;
      case "marker": case "marker_array": case "pose_with_covariance": case "polygon": drawMarkers(L); break;
      default: break;
    }
  }
  function updateFollow() {
    if (!view.follow) return;
    const p = framePose(view.follow);
    if (!p) return;
    view.cx = p[0]; view.cy = p[1];
    if (view.rotate) view.angle = p[2] - Math.PI / 2;
  }
  function draw() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.fillStyle = "#303030"; g.fillRect(0, 0, canvas.width, canvas.height);
    updateFollow();
    worldTransform();
    const cfg = data.config;
    if (cfg) {
      // maps drawn behind everything first (rviz's Draw Behind), then panel order
      cfg.displays.forEach((d, i) => { if (d.enabled && d.kind === "map" && d.options.draw_behind) drawDisplay(d, i); });
      cfg.displays.forEach((d, i) => { if (d.enabled && !(d.kind === "map" && d.options.draw_behind)) drawDisplay(d, i); });
    }
    if (drag && drag.tool !== "move") {
      const color = drag.tool === "goal" ? "rgb(80,255,80)" : (drag.tool === "point" ? "rgb(255,220,80)" : "rgb(80,160,255)");
      arrowWorld(drag.wx, drag.wy, drag.yaw, px(50), color, px(3));
    }
    g.setTransform(1, 0, 0, 1, 0, 0);
    data.frames += 1;
  }
  // one scheduler for both views: the 2D canvas here, or view3d.js's frame (viz.draw3d)
  redraw.draw = () => {
    if (!view.mode || view.mode === "2D") draw();
    else if (window.viz.draw3d) window.viz.draw3d();
  };
  new ResizeObserver(requestDraw).observe($("main"));

  // ------------------------------------------------------------------ mouse
  function canvasXY(ev) {
    const r = canvas.getBoundingClientRect();
    return [ev.clientX - r.left, ev.clientY - r.top];
  }
  canvas.addEventListener("contextmenu", (ev) => ev.preventDefault());
  canvas.addEventListener("mousedown", (ev) => {
    if (view.mode && view.mode !== "2D") return;
    const [x, y] = canvasXY(ev);
    const [wx, wy] = screenToWorld(x, y);
    const mode = ev.button === 2 || (ev.button === 0 && ev.shiftKey && tool === "move") ? "rotate" : tool;
    drag = { tool: mode, px: x, py: y, wx, wy, yaw: view.angle, cx: view.cx, cy: view.cy, angle: view.angle };
    canvas.focus();
    if (mode !== "move" && mode !== "rotate") requestDraw();  // the tool's arrow
  });
  window.addEventListener("mousemove", (ev) => {
    if (!drag || (view.mode && view.mode !== "2D")) return;
    const [x, y] = canvasXY(ev);
    requestDraw();
    if (drag.tool === "move") {
      const c = Math.cos(view.angle), s = Math.sin(view.angle);
      const rx = -(x - drag.px) / view.scale, ry = (y - drag.py) / view.scale;
      view.cx = drag.cx + c * rx - s * ry; view.cy = drag.cy + s * rx + c * ry;
      view.placed = true;
      if (view.follow) { view.follow = ""; $("follow").value = ""; }
    } else if (drag.tool === "rotate") {
      view.angle = drag.angle + (x - drag.px) * 0.01;
    } else if (Math.hypot(x - drag.px, y - drag.py) > 3) {
      // the drag's direction on screen, turned into the world by the view's rotation
      drag.yaw = Math.atan2(-(y - drag.py), x - drag.px) + view.angle;
    }
  });
  window.addEventListener("mouseup", () => {
    if (!drag || (view.mode && view.mode !== "2D")) return;
    const d = drag; drag = null;
    requestDraw();
    if (d.tool === "goal" || d.tool === "initialpose") send({ type: d.tool, x: d.wx, y: d.wy, yaw: d.yaw });
    else if (d.tool === "point") send({ type: "point", x: d.wx, y: d.wy });
    if (d.tool !== "move" && d.tool !== "rotate") setTool("move");  // rviz drops back to the camera tool
  });
  canvas.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    if (view.mode && view.mode !== "2D") return;
    const [x, y] = canvasXY(ev);
    const [wx, wy] = screenToWorld(x, y);
    view.scale = Math.min(2000, Math.max(0.5, view.scale * Math.exp(-ev.deltaY * 0.001)));
    requestDraw();
    if (view.follow) return;  // zoom about the followed frame
    const [nx, ny] = screenToWorld(x, y);
    view.cx += wx - nx; view.cy += wy - ny;
  }, { passive: false });

  function setTool(t) {
    tool = t;
    for (const b of document.querySelectorAll("#toolbar button[data-tool]")) b.classList.toggle("active", b.dataset.tool === t);
  }
  for (const b of document.querySelectorAll("#toolbar button[data-tool]")) b.onclick = () => setTool(b.dataset.tool);

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

  const configHooks = [];
  // view: setting a property through it asks for a frame (redraw.watch)
  window.viz = { view: redraw.watch(view), data, conn, worldToScreen, screenToWorld, setTool, send, PALETTES,
                 configHooks, getTool: () => tool, framePose, redraw, requestDraw };
  connect();
  requestDraw();
})();
