// roverlab dashboard: the 3D view (three.js, vendored). rviz's Orbit, TopDownOrtho and
// ThirdPersonFollower camera controllers over the data app.js keeps in window.viz.data.
// z is up, as in ROS; every pose comes in the fixed frame. What the displays put in the scene:
// displays3d.js.
import * as THREE from "three";
import { setLineResolution } from "./markers3d.js";
import { scene, frame3, updateScene, arrowMesh, tfLabels } from "./displays3d.js";

const viz = window.viz;
const data = viz.data;
const requestDraw = viz.requestDraw;  // redraw.js: a frame only when something drawn changed
const host = document.getElementById("main");
const canvas2d = document.getElementById("view");
const canvas = document.createElement("canvas");
canvas.id = "view3d"; canvas.tabIndex = 0;
canvas.style.cssText = "width:100%;height:100%;display:none;outline:none;background:#303030";
host.appendChild(canvas);
const labels = document.createElement("div");
labels.id = "tf-labels";
labels.style.cssText = "position:absolute;inset:0;pointer-events:none;overflow:hidden;display:none";
host.appendChild(labels);

// (displays3d.js turns three's colour management off before any colour is made)
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, powerPreference: "high-performance" });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0x303030);
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;  // colours pass through as given, as rviz's

const persp = new THREE.PerspectiveCamera(60, 1, 0.01, 2000);
persp.up.set(0, 0, 1);
const ortho = new THREE.OrthographicCamera(-1, 1, 1, -1, -1000, 1000);
ortho.up.set(0, 1, 0);

// rviz's view controllers: Orbit (focal point, distance, yaw, pitch), TopDownOrtho
// (centre x, y, scale px/m, angle), ThirdPersonFollower (an orbit about a frame, turning with it)
const cam = { mode: "2D", focal: new THREE.Vector3(0, 0, 0), distance: 10, yaw: 0.785, pitch: 0.785,
              x: 0, y: 0, scale: 50, angle: 0, target: "", frames: 0, fps: 0, resolution: 1,
              adaptive: true, fpsCapable: 0 };
viz.cam = viz.redraw.watch(cam);  // setting a property through viz.cam asks for a frame

function setMode(mode) {
  cam.mode = mode;
  viz.view.mode = mode;
  const is3d = mode !== "2D";
  canvas.style.display = is3d ? "block" : "none";
  labels.style.display = is3d ? "block" : "none";
  canvas2d.style.display = is3d ? "none" : "block";
  const sel = document.getElementById("view-mode");
  if (sel && sel.value !== mode) sel.value = mode;
  requestDraw();
}
viz.setViewMode = setMode;

function applyConfigView(view) {
  if (!view || !view.mode) return;
  if (view.focal_point) cam.focal.set(...view.focal_point);
  if (view.distance !== undefined) cam.distance = Math.max(0.05, view.distance);
  if (view.yaw !== undefined) cam.yaw = view.yaw;
  if (view.pitch !== undefined) cam.pitch = view.pitch;
  if (view.x !== undefined) { cam.x = view.x; cam.y = view.y; cam.scale = view.scale || 50; cam.angle = view.angle || 0; }
  cam.target = view.target_frame || "";
  setMode(view.mode);
}
let configViewSeen = false;
viz.configHooks.push((config) => {
  if (!configViewSeen && config.view) { configViewSeen = true; applyConfigView(config.view); }
});
if (data.config && data.config.view) { configViewSeen = true; applyConfigView(data.config.view); }

function followFrame() {
  const s = data.state;
  if (cam.target && frame3(cam.target)) return cam.target;
  if (s && s.frames3) for (const f of ["base_footprint", "base_link"]) if (s.frames3[f]) return f;
  return null;
}
function yawOf(q) { return Math.atan2(2 * (q[6] * q[5] + q[3] * q[4]), 1 - 2 * (q[4] * q[4] + q[5] * q[5])); }

function placeCamera(w, h) {
  if (cam.mode === "TopDownOrtho") {
    const hw = w / 2 / cam.scale, hh = h / 2 / cam.scale;
    Object.assign(ortho, { left: -hw, right: hw, top: hh, bottom: -hh });
    ortho.position.set(cam.x, cam.y, 100);
    ortho.up.set(-Math.sin(cam.angle), Math.cos(cam.angle), 0);
    ortho.lookAt(cam.x, cam.y, 0);
    ortho.updateProjectionMatrix();
    return ortho;
  }
  let yaw = cam.yaw;
  const focal = cam.focal.clone();
  if (cam.mode === "ThirdPersonFollower") {
    const f = followFrame(), p = f ? frame3(f) : null;
    if (p) { focal.set(p[0], p[1], p[2]); yaw += yawOf([0, 0, 0, p[3], p[4], p[5], p[6]]); }
  }
  const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch);
  persp.position.set(focal.x + cam.distance * Math.cos(yaw) * cp, focal.y + cam.distance * Math.sin(yaw) * cp,
                     focal.z + cam.distance * sp);
  persp.lookAt(focal);
  persp.aspect = w / h; persp.updateProjectionMatrix();
  return persp;
}

// TF names as HTML labels, pushed apart so none overlap (rviz draws them over each other)
const labelPool = [];
function placeLabels(camera, w, h) {
  const items = [];
  const v = new THREE.Vector3();
  for (const [name, p] of tfLabels) {
    v.set(p[0], p[1], p[2]).project(camera);
    if (v.z > 1 || v.z < -1) continue;
    items.push({ name, x: (v.x + 1) / 2 * w + 6, y: (1 - v.y) / 2 * h - 14 });
  }
  items.sort((a, b) => a.y - b.y || a.x - b.x);
  const placed = [];
  for (const it of items) {
    const width = 7 * it.name.length + 6, height = 14;
    for (let tries = 0; tries < 40; tries++) {
      const hit = placed.find((q) => it.x < q.x + q.w && q.x < it.x + width && it.y < q.y + q.h && q.y < it.y + height);
      if (!hit) break;
      it.y = hit.y + hit.h + 1;
    }
    placed.push({ x: it.x, y: it.y, w: width, h: height, name: it.name });
  }
  while (labelPool.length < placed.length) {
    const el = document.createElement("div"); el.className = "tf-label";
    el.style.cssText = "position:absolute;font:11px sans-serif;color:#fff;background:rgba(0,0,0,0.45);padding:0 3px;white-space:nowrap";
    labels.appendChild(el); labelPool.push(el);
  }
  labelPool.forEach((el, i) => {  // the DOM is touched only where a label changed (style writes cost paint)
    const q = placed[i], want = q ? `${q.name} ${q.x.toFixed(0)} ${q.y.toFixed(0)}` : "";
    if (el.dataset.was === want) return;
    el.dataset.was = want;
    if (!q) { el.style.display = "none"; return; }
    el.style.display = "block"; el.textContent = q.name;
    el.style.transform = `translate(${q.x.toFixed(0)}px, ${q.y.toFixed(0)}px)`;
  });
  viz.tfLabelBoxes = placed;
}

// ------------------------------------------------------------------ tools
const toolArrow = arrowMesh(1, 0x50ff50, 1);
toolArrow.visible = false; scene.add(toolArrow);
const ground = new THREE.Plane(new THREE.Vector3(0, 0, 1), 0);
const raycaster = new THREE.Raycaster();
let camera = persp;
function groundPoint(px, py) {
  // the mouse ray cast onto the ground plane z = 0 of the fixed frame
  const r = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2((px - r.left) / r.width * 2 - 1, -((py - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  const hit = new THREE.Vector3();
  return raycaster.ray.intersectPlane(ground, hit) ? hit : null;
}
viz.groundPoint = groundPoint;
viz.worldToScreen3 = (x, y, z) => {
  const r = canvas.getBoundingClientRect(), v = new THREE.Vector3(x, y, z).project(camera);
  return [(v.x + 1) / 2 * r.width, (1 - v.y) / 2 * r.height];
};

let drag = null;
canvas.addEventListener("contextmenu", (ev) => ev.preventDefault());
canvas.addEventListener("mousedown", (ev) => {
  canvas.focus();
  const tool = viz.getTool();
  if (tool !== "move" && ev.button === 0) {
    const p = groundPoint(ev.clientX, ev.clientY);
    if (!p) return;
    drag = { tool, x: ev.clientX, y: ev.clientY, p, yaw: 0 };
    requestDraw();  // the tool's arrow
    return;
  }
  const mode = ev.button === 1 || (ev.button === 0 && ev.shiftKey) ? "pan" : ev.button === 2 ? "zoom" : "rotate";
  drag = { tool: "camera", mode, x: ev.clientX, y: ev.clientY, cam: { ...cam, focal: cam.focal.clone() } };
});
window.addEventListener("mousemove", (ev) => {
  if (!drag || cam.mode === "2D") return;
  const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
  requestDraw();
  if (drag.tool !== "camera") {
    const q = groundPoint(ev.clientX, ev.clientY);
    if (q && Math.hypot(dx, dy) > 3) drag.yaw = Math.atan2(q.y - drag.p.y, q.x - drag.p.x);
    return;
  }
  const c0 = drag.cam;
  if (cam.mode === "TopDownOrtho") {
    if (drag.mode === "rotate" && !ev.shiftKey && ev.buttons === 1) {  // left drag pans the top view
      const c = Math.cos(cam.angle), s = Math.sin(cam.angle);
      cam.x = c0.x - (c * dx + s * dy) / cam.scale; cam.y = c0.y - (s * dx - c * dy) / cam.scale;
    } else if (drag.mode === "zoom") cam.scale = Math.max(0.5, c0.scale * Math.exp(-dy * 0.01));
    else cam.angle = c0.angle + dx * 0.01;
    return;
  }
  if (drag.mode === "rotate") {
    cam.yaw = c0.yaw - dx * 0.01;
    cam.pitch = Math.max(-1.55, Math.min(1.55, c0.pitch + dy * 0.01));
  } else if (drag.mode === "zoom") {
    cam.distance = Math.max(0.05, c0.distance * Math.exp(dy * 0.01));
  } else {  // pan the focal point in the camera's plane
    const k = cam.distance * 0.0015, right = new THREE.Vector3(), up = new THREE.Vector3();
    right.setFromMatrixColumn(persp.matrixWorld, 0); up.setFromMatrixColumn(persp.matrixWorld, 1);
    cam.focal.copy(c0.focal).addScaledVector(right, -dx * k).addScaledVector(up, dy * k);
  }
});
window.addEventListener("mouseup", () => {
  if (!drag) return;
  const d = drag; drag = null;
  requestDraw();
  if (d.tool === "goal" || d.tool === "initialpose") viz.send({ type: d.tool, x: d.p.x, y: d.p.y, yaw: d.yaw });
  else if (d.tool === "point") viz.send({ type: "point", x: d.p.x, y: d.p.y });
  if (d.tool !== "camera") viz.setTool("move");
});
canvas.addEventListener("wheel", (ev) => {
  ev.preventDefault();
  if (cam.mode === "TopDownOrtho") cam.scale = Math.min(2000, Math.max(0.5, cam.scale * Math.exp(-ev.deltaY * 0.001)));
  else cam.distance = Math.max(0.05, cam.distance * Math.exp(ev.deltaY * 0.001));
  requestDraw();
}, { passive: false });

// ------------------------------------------------------------------- loop
// Drawn by redraw.js's scheduler (viz.draw3d) only when something changed, at most Frame
// Rate times a second. cam.fps: frames drawn per second (low when little changes).
let fpsT0 = performance.now(), fpsN = 0, lastSync = -Infinity;
const costs = [];  // ms per needed frame, GPU work included (see below)
function frame() {
  const w = host.clientWidth, h = host.clientHeight;
  const pr = renderer.getPixelRatio();
  if (canvas.width !== Math.floor(w * pr) || canvas.height !== Math.floor(h * pr)) renderer.setSize(w, h, false);
  const t0 = performance.now();
  updateScene();
  const t1 = performance.now();
  camera = placeCamera(w, h);
  if (drag && drag.tool !== "camera") {
    const c = drag.tool === "goal" ? 0x50ff50 : drag.tool === "point" ? 0xffdc50 : 0x50a0ff;
    toolArrow.visible = true; toolArrow.position.set(drag.p.x, drag.p.y, 0.05); toolArrow.rotation.set(0, 0, drag.yaw);
    toolArrow.children.forEach((m) => m.material.color.setHex(c));
  } else toolArrow.visible = false;
  setLineResolution(w, h);
  renderer.render(scene, camera);
  const t2 = performance.now();
  // what a frame costs, the (software) GPU's work included: at most 4 times a second a drawn
  // frame waits for it (a one-pixel read). Only frames that were needed are judged, so an
  // idle view never changes its resolution.
  if (cam.adaptive && t2 - lastSync >= 250) {
    const gl = renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    lastSync = performance.now();
    costs.push(lastSync - t0);
  }
  placeLabels(camera, w, h);
  cam.msUpdate = 0.9 * (cam.msUpdate || 0) + 0.1 * (t1 - t0);
  cam.msRender = 0.9 * (cam.msRender || 0) + 0.1 * (t2 - t1);
  cam.frames += 1; fpsN += 1;
  const now = performance.now();
  if (now - fpsT0 >= 1000) {
    cam.fps = fpsN * 1000 / (now - fpsT0); fpsN = 0; fpsT0 = now;
    adaptResolution();
  }
}
viz.draw3d = frame;
// adaptive resolution: a slow (software) renderer draws fewer pixels, down to half per axis,
// to keep the view interactive (>= 28 frames a second); back to full resolution when there
// is headroom (> 50)
function adaptResolution() {
  const r = cam.resolution;
  if (!cam.adaptive) cam.resolution = 1;
  else if (costs.length >= 3) {
    cam.fpsCapable = 1000 * costs.length / costs.reduce((a, b) => a + b, 0);
    costs.length = 0;
    if (cam.fpsCapable < 28 && r > 0.5) cam.resolution = Math.max(0.5, r - 0.125);
    else if (cam.fpsCapable > 50 && r < 1) cam.resolution = Math.min(1, r + 0.125);
  }
  if (cam.resolution !== r) {
    renderer.setPixelRatio(cam.resolution * (window.devicePixelRatio || 1));
    costs.length = 0;
    requestDraw();  // the canvas was resized (and cleared)
  }
}
// benchmarks: n frames rendered back to back, each waited for (a one-pixel read), in ms per frame
viz.renderSync = (n) => {
  const gl = renderer.getContext(), px = new Uint8Array(4), t0 = performance.now();
  for (let i = 0; i < n; i++) { renderer.render(scene, camera); gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px); }
  return (performance.now() - t0) / n;
};
const sel = document.getElementById("view-mode");
if (sel) sel.onchange = () => setMode(sel.value);
requestDraw();
