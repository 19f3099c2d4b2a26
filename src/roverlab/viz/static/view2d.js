// roverlab dashboard: the 2D view, a top-down rviz on one canvas (#view): the displays drawn
// with the canvas 2D API, the mouse (camera and tools) and the toolbar's tools, follow and
// rotation. app.js sets it up on the page's state (window.vizView2d). No build step.
"use strict";
window.vizView2d = ({ $, view, data, send, redraw, requestDraw, expirePoints }) => {
  const canvas = $("view");
  const g = canvas.getContext("2d");
  let tool = "move";
  let drag = null;

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
    expirePoints(d, L);
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
  $("follow").onchange = () => { view.follow = $("follow").value; view.placed = true; requestDraw(); };
  $("rotate-follow").onchange = () => { view.rotate = $("rotate-follow").checked; requestDraw(); };
  $("rot-left").onclick = () => { view.angle -= Math.PI / 12; requestDraw(); };
  $("rot-right").onclick = () => { view.angle += Math.PI / 12; requestDraw(); };
  $("rot-reset").onclick = () => { view.angle = 0; view.rotate = false; $("rotate-follow").checked = false; requestDraw(); };

  return { worldToScreen, screenToWorld, setTool, getTool: () => tool, framePose };
};
