// roverlab dashboard: a top-down rviz on one canvas. No build step, no dependencies.
"use strict";
(() => {
  const KIND_MAP = 1, KIND_SCAN = 2, KIND_IMAGE = 3;
  const SCAN_COLOR = "rgb(255,0,0)";
  const canvas = document.getElementById("view");
  const g = canvas.getContext("2d");
  const statusEl = document.getElementById("status");
  const imageSelect = document.getElementById("image-topic");
  const cameraImg = document.getElementById("camera");
  const driveEl = document.getElementById("drive-state");

  // view: world point (cx, cy) at the canvas centre, `scale` pixels per metre
  const view = { cx: 0, cy: 0, scale: 50, placed: false };
  const data = { map: null, mapCanvas: null, scan: null, state: null, frames: 0 };
  let tool = "move";
  let drag = null;

  function worldToScreen(x, y) {
    return [canvas.width / 2 + (x - view.cx) * view.scale,
            canvas.height / 2 - (y - view.cy) * view.scale];
  }
  function screenToWorld(px, py) {
    return [view.cx + (px - canvas.width / 2) / view.scale,
            view.cy - (py - canvas.height / 2) / view.scale];
  }

  // ------------------------------------------------------------------ socket
  const token = new URLSearchParams(location.search).get("token");
  const wsUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws" +
    (token ? "?token=" + encodeURIComponent(token) : "");
  let ws = null;
  function send(obj) { if (ws && ws.readyState === 1) ws.send(JSON.stringify(obj)); }
  function connect() {
    ws = new WebSocket(wsUrl);
    ws.binaryType = "arraybuffer";
    ws.onopen = () => { statusEl.textContent = "connected"; };
    ws.onclose = () => { statusEl.textContent = "disconnected"; setTimeout(connect, 1000); };
    ws.onmessage = (ev) => {
      if (typeof ev.data === "string") onState(JSON.parse(ev.data));
      else onBinary(ev.data);
    };
  }

  function onBinary(buf) {
    const dv = new DataView(buf);
    const kind = dv.getUint8(0);
    if (kind === KIND_MAP) {
      const w = dv.getUint32(4, true), h = dv.getUint32(8, true);
      const res = dv.getFloat32(12, true);
      const ox = dv.getFloat32(16, true), oy = dv.getFloat32(20, true), oyaw = dv.getFloat32(24, true);
      const cells = new Int8Array(buf, 28, w * h);
      const off = document.createElement("canvas");
      off.width = w; off.height = h;
      const octx = off.getContext("2d");
      const img = octx.createImageData(w, h);
      for (let r = 0; r < h; r++) {
        for (let c = 0; c < w; c++) {
          const v = cells[r * w + c];
          // row 0 of the grid is the bottom of the map: flip rows into image space
          const i = ((h - 1 - r) * w + c) * 4;
          let shade;
          if (v < 0) { img.data[i] = 0x70; img.data[i + 1] = 0x89; img.data[i + 2] = 0x86; }
          else { shade = Math.round(254 - (v / 100) * 254);
                 img.data[i] = shade; img.data[i + 1] = shade; img.data[i + 2] = shade; }
          img.data[i + 3] = 255;
        }
      }
      octx.putImageData(img, 0, 0);
      data.map = { w, h, res, ox, oy, oyaw };
      data.mapCanvas = off;
      if (!view.placed && !(data.state && data.state.frames.base_link)) {
        view.cx = ox + w * res / 2; view.cy = oy + h * res / 2;
      }
    } else if (kind === KIND_SCAN) {
      const n = dv.getUint32(4, true);
      data.scan = new Float32Array(buf, 8, n * 2);
    } else if (kind === KIND_IMAGE) {
      const blob = new Blob([new Uint8Array(buf, 4)], { type: "image/jpeg" });
      const old = cameraImg.src;
      cameraImg.src = URL.createObjectURL(blob);
      if (old.startsWith("blob:")) URL.revokeObjectURL(old);
    }
  }

  function onState(msg) {
    if (msg.type !== "state") return;
    data.state = msg;
    const base = msg.frames.base_footprint || msg.frames.base_link;
    if (!view.placed && base) { view.cx = base[0]; view.cy = base[1]; view.placed = true; }
    const topics = msg.image_topics || [];
    const have = Array.from(imageSelect.options).map((o) => o.value).filter((v) => v);
    if (topics.join() !== have.join()) {
      const current = imageSelect.value;
      imageSelect.innerHTML = '<option value="">(no image topic)</option>';
      for (const t of topics) {
        const o = document.createElement("option"); o.value = t; o.textContent = t;
        imageSelect.appendChild(o);
      }
      imageSelect.value = topics.includes(current) ? current : (topics[0] || "");
      if (imageSelect.value) send({ type: "image_topic", topic: imageSelect.value });
    }
    statusEl.textContent = "fixed frame: " + msg.fixed_frame;
  }
  imageSelect.onchange = () => { if (imageSelect.value) send({ type: "image_topic", topic: imageSelect.value }); };

  // ---------------------------------------------------------------- drawing
  function drawGrid() {
    const [x0, y1] = screenToWorld(0, 0), [x1, y0] = screenToWorld(canvas.width, canvas.height);
    g.strokeStyle = "rgba(160,160,164,0.5)"; g.lineWidth = 1; g.beginPath();
    for (let x = Math.floor(x0); x <= x1; x++) { const [sx] = worldToScreen(x, 0); g.moveTo(sx, 0); g.lineTo(sx, canvas.height); }
    for (let y = Math.floor(y0); y <= y1; y++) { const [, sy] = worldToScreen(0, y); g.moveTo(0, sy); g.lineTo(canvas.width, sy); }
    g.stroke();
  }
  function framePose(name) {
    const s = data.state;
    if (!s) return null;
    if (name === s.fixed_frame) return [0, 0, 0];
    return s.frames[name] || null;
  }
  function drawMap() {
    const m = data.map;
    if (!m) return;
    const fp = framePose(data.state ? data.state.map_frame : "map") || [0, 0, 0];
    const [sx, sy] = worldToScreen(fp[0], fp[1]);
    g.save();
    g.imageSmoothingEnabled = false;
    g.translate(sx, sy); g.scale(view.scale, -view.scale); g.rotate(fp[2]);
    g.translate(m.ox, m.oy); g.rotate(m.oyaw);
    // the offscreen image has its first row at the top: draw it flipped back upright
    g.scale(1, -1);
    g.drawImage(data.mapCanvas, 0, -m.h * m.res, m.w * m.res, m.h * m.res);
    g.restore();
  }
  function drawScan() {
    const p = data.scan;
    if (!p) return;
    g.fillStyle = SCAN_COLOR;
    for (let i = 0; i < p.length; i += 2) {
      const [sx, sy] = worldToScreen(p[i], p[i + 1]);
      g.fillRect(sx - 1.5, sy - 1.5, 3, 3);
    }
  }
  function drawRobot() {
    const s = data.state;
    if (!s) return;
    for (const part of s.robot) {
      const [r, gg, b, a] = part.rgba;
      g.fillStyle = `rgba(${Math.round(r * 255)},${Math.round(gg * 255)},${Math.round(b * 255)},${a})`;
      g.beginPath();
      part.points.forEach(([x, y], i) => { const [sx, sy] = worldToScreen(x, y); if (i) g.lineTo(sx, sy); else g.moveTo(sx, sy); });
      g.closePath(); g.fill();
    }
  }
  function arrow(x, y, yaw, len, color, width) {
    const [sx, sy] = worldToScreen(x, y);
    const ex = sx + Math.cos(yaw) * len, ey = sy - Math.sin(yaw) * len;
    g.strokeStyle = color; g.fillStyle = color; g.lineWidth = width;
    g.beginPath(); g.moveTo(sx, sy); g.lineTo(ex, ey); g.stroke();
    const hx = Math.cos(yaw), hy = -Math.sin(yaw), head = Math.max(6, len * 0.3);
    g.beginPath(); g.moveTo(ex, ey);
    g.lineTo(ex - hx * head - hy * head * 0.5, ey - hy * head + hx * head * 0.5);
    g.lineTo(ex - hx * head + hy * head * 0.5, ey - hy * head - hx * head * 0.5);
    g.closePath(); g.fill();
  }
  function drawTf() {
    const s = data.state;
    if (!s) return;
    const len = Math.max(8, 0.1 * view.scale);
    g.lineWidth = 2;
    for (const [, [x, y, yaw]] of Object.entries(s.frames)) {
      const [sx, sy] = worldToScreen(x, y);
      g.strokeStyle = "rgb(230,40,40)"; g.beginPath(); g.moveTo(sx, sy);
      g.lineTo(sx + Math.cos(yaw) * len, sy - Math.sin(yaw) * len); g.stroke();
      g.strokeStyle = "rgb(40,200,40)"; g.beginPath(); g.moveTo(sx, sy);
      g.lineTo(sx - Math.sin(yaw) * len, sy - Math.cos(yaw) * len); g.stroke();
    }
  }
  function drawOdom() {
    const s = data.state;
    if (s && s.odom) arrow(s.odom[0], s.odom[1], s.odom[2], Math.max(20, 0.4 * view.scale), "rgb(255,200,0)", 2);
  }
  function draw() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    g.fillStyle = "#303030"; g.fillRect(0, 0, canvas.width, canvas.height);
    drawMap(); drawGrid(); drawScan(); drawRobot(); drawTf(); drawOdom();
    if (drag && drag.tool !== "move") {
      const color = drag.tool === "goal" ? "rgb(80,255,80)" : "rgb(80,160,255)";
      arrow(drag.wx, drag.wy, drag.yaw, 40, color, 3);
    }
    data.frames += 1;
    requestAnimationFrame(draw);
  }

  // ------------------------------------------------------------------ mouse
  function canvasXY(ev) {
    const r = canvas.getBoundingClientRect();
    return [ev.clientX - r.left, ev.clientY - r.top];
  }
  canvas.addEventListener("mousedown", (ev) => {
    const [px, py] = canvasXY(ev);
    const [wx, wy] = screenToWorld(px, py);
    drag = { tool, px, py, wx, wy, yaw: 0, cx: view.cx, cy: view.cy };
    canvas.focus();
  });
  window.addEventListener("mousemove", (ev) => {
    if (!drag) return;
    const [px, py] = canvasXY(ev);
    if (drag.tool === "move") {
      view.cx = drag.cx - (px - drag.px) / view.scale;
      view.cy = drag.cy + (py - drag.py) / view.scale;
      view.placed = true;
    } else if (Math.hypot(px - drag.px, py - drag.py) > 3) {
      drag.yaw = Math.atan2(-(py - drag.py), px - drag.px);
    }
  });
  window.addEventListener("mouseup", () => {
    if (!drag) return;
    const d = drag; drag = null;
    if (d.tool === "goal" || d.tool === "initialpose") send({ type: d.tool, x: d.wx, y: d.wy, yaw: d.yaw });
    else if (d.tool === "point") send({ type: "point", x: d.wx, y: d.wy });
    if (d.tool !== "move") setTool("move");  // rviz drops back to the camera tool
  });
  canvas.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    const [px, py] = canvasXY(ev);
    const [wx, wy] = screenToWorld(px, py);
    view.scale = Math.min(2000, Math.max(2, view.scale * Math.exp(-ev.deltaY * 0.001)));
    const [nx, ny] = screenToWorld(px, py);
    view.cx += wx - nx; view.cy += wy - ny;
  }, { passive: false });

  function setTool(t) {
    tool = t;
    for (const b of document.querySelectorAll("#toolbar button")) b.classList.toggle("active", b.dataset.tool === t);
  }
  for (const b of document.querySelectorAll("#toolbar button")) b.onclick = () => setTool(b.dataset.tool);

  // ------------------------------------------------------------------ drive
  const DRIVE_KEYS = new Set(["i", "j", "l", ",", "k", "u", "o", "m", ".", "I", "J", "L", "<", "U", "O", "M", ">"]);
  let held = null;
  window.addEventListener("keydown", (ev) => {
    if (ev.target === imageSelect || !DRIVE_KEYS.has(ev.key)) return;
    held = ev.key; send({ type: "key", key: ev.key }); driveEl.textContent = "key " + ev.key;
  });
  window.addEventListener("keyup", (ev) => {
    if (ev.key !== held) return;
    held = null; send({ type: "key", key: "k" }); driveEl.textContent = "stopped";
  });
  setInterval(() => { if (held) send({ type: "key", key: held }); }, 100);  // keep-alive

  window.viz = { view, data, worldToScreen, screenToWorld, setTool };
  connect();
  requestAnimationFrame(draw);
})();
