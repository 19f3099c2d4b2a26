// roverlab dashboard: the 3D view's scene (three.js): what each display puts in it, one object
// per display slot, brought up to date with window.viz.data before each frame (updateScene).
// view3d.js owns the renderer, the cameras and the mouse. z is up, as in ROS; every pose comes
// in the fixed frame.
import * as THREE from "three";
import { STLLoader } from "./vendor/three/addons/loaders/STLLoader.js";
import { ColladaLoader } from "./vendor/three/addons/loaders/ColladaLoader.js";
import { buildMarker, markerShapeKey } from "./markers3d.js";

const viz = window.viz;
const data = viz.data;
const requestDraw = viz.requestDraw;  // redraw.js: a frame only when something drawn changed

THREE.ColorManagement.enabled = false;  // colours pass through as given (rviz's 0..1 RGB)
export const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(3, -2, 8); scene.add(sun);
THREE.Object3D.DEFAULT_UP.set(0, 0, 1);

export function frame3(name) {
  const s = data.state;
  if (!s || !s.frames3) return null;
  if (!name || name === s.fixed_frame) return [0, 0, 0, 0, 0, 0, 1];
  return s.frames3[name] || null;
}

// ----------------------------------------------------------------- displays
const objects = new Map();  // slot -> { key, obj, ... }
viz.objects3d = objects;  // for tests: what each display drew
function slotObject(slot, key, make) {
  let o = objects.get(slot);
  if (o && o.key !== key) { scene.remove(o.obj); dispose(o.obj); o = null; }
  if (!o) { o = { key, obj: make() }; objects.set(slot, o); scene.add(o.obj); }
  o.seen = true;
  return o;
}
function dispose(obj) {
  obj.traverse((c) => {
    if (c.geometry) c.geometry.dispose();
    if (c.material) {
      if (c.material.map) c.material.map.dispose();
      if (c.material.uniforms) for (const u of Object.values(c.material.uniforms)) if (u.value && u.value.isTexture) u.value.dispose();
      c.material.dispose();
    }
  });
}
function setPose(obj, p) {
  obj.position.set(p[0], p[1], p[2]);
  obj.quaternion.set(p[3], p[4], p[5], p[6]);
}
const col = (c, a) => new THREE.Color(c[0] / 255, c[1] / 255, c[2] / 255);

function updateGrid(slot, d) {
  const o = d.options, key = `grid ${o.cell_size} ${o.cell_count} ${o.color} ${o.alpha}`;
  const e = slotObject(slot, key, () => {
    const n = Math.max(1, o.cell_count), half = n * o.cell_size / 2, pts = [];
    for (let i = 0; i <= n; i++) {
      const v = -half + i * o.cell_size;
      pts.push(v, -half, 0, v, half, 0, -half, v, 0, half, v, 0);
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.Float32BufferAttribute(pts, 3));
    return new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ color: col(o.color), transparent: true, opacity: o.alpha }));
  });
  const p = frame3(o.reference_frame);
  e.obj.visible = !!p;
  if (p) setPose(e.obj, p);
}

// The map as rviz draws it: the int8 cells as a one-byte texture and the colour scheme as a
// 256-entry palette texture, looked up per pixel (a quarter of an RGBA texture's memory
// traffic, and a scheme change or a patch re-uploads only bytes)
const MAP_VERTEX = `varying vec2 vUv;
void main() { vUv = uv; gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`;
const MAP_FRAGMENT = `uniform sampler2D cells; uniform sampler2D palette; uniform float alpha; varying vec2 vUv;
void main() {
  float v = texture2D(cells, vUv).r;
  vec4 c = texture2D(palette, vec2((v * 255.0 + 0.5) / 256.0, 0.5));
  if (c.a * alpha <= 0.0) discard;
  gl_FragColor = vec4(c.rgb, c.a * alpha);
}`;
function paletteTexture(scheme) {
  const pal = viz.PALETTES[scheme] || viz.PALETTES.map;
  const tex = new THREE.DataTexture(new Uint8Array(pal.buffer.slice(0)), 256, 1, THREE.RGBAFormat);
  tex.magFilter = tex.minFilter = THREE.NearestFilter; tex.needsUpdate = true;
  return tex;
}
// Far from the camera many cells fall on one pixel. The cells carry a chain of coarser levels
// (mipmaps) built by "the most occupied wins" (signed max: unknown -1 < free 0 < occupied
// 1..100), so a zoomed-out map keeps its walls instead of shimmering between cells, and the
// renderer reads a few neighbouring texels per pixel instead of scattering over the whole
// texture (with software WebGL the map plane was most of a frame's cost)
function mapLevels(m) {
  const levels = [{ data: new Uint8Array(m.cells.buffer, m.cells.byteOffset, m.w * m.h), width: m.w, height: m.h }];
  for (let w = m.w, h = m.h; w > 1 || h > 1;) {
    w = Math.max(1, w >> 1); h = Math.max(1, h >> 1);
    levels.push({ data: new Uint8Array(w * h), width: w, height: h });
  }
  reduceLevels(levels, 0, 0, m.w, m.h);
  return levels;
}
function reduceLevels(levels, x0, y0, x1, y1) {  // recompute the coarse levels over a window of level 0
  for (let k = 1; k < levels.length; k++) {
    const a = levels[k - 1], b = levels[k];
    const src = new Int8Array(a.data.buffer, a.data.byteOffset, a.width * a.height);
    const dst = new Int8Array(b.data.buffer, b.data.byteOffset, b.width * b.height);
    x0 >>= 1; y0 >>= 1; x1 = Math.min(b.width, (x1 + 1) >> 1); y1 = Math.min(b.height, (y1 + 1) >> 1);
    for (let y = y0; y < y1; y++) {
      const r0 = Math.min(2 * y, a.height - 1) * a.width, r1 = Math.min(2 * y + 1, a.height - 1) * a.width;
      for (let x = x0; x < x1; x++) {
        const c0 = Math.min(2 * x, a.width - 1), c1 = Math.min(2 * x + 1, a.width - 1);
        dst[y * b.width + x] = Math.max(src[r0 + c0], src[r0 + c1], src[r1 + c0], src[r1 + c1]);
      }
    }
  }
}
function updateMap(slot, d, L, info) {
  const m = L.map;
  if (!m) return;
  const e = slotObject(slot, `map ${m.w} ${m.h} ${m.res} ${m.ox} ${m.oy} ${m.oyaw}`, () => {
    const levels = mapLevels(m);
    m.dirty3 = null;
    const cells = new THREE.DataTexture(levels[0].data, m.w, m.h, THREE.RedFormat, THREE.UnsignedByteType);
    cells.mipmaps = levels;
    cells.magFilter = THREE.NearestFilter; cells.minFilter = THREE.NearestMipmapNearestFilter;
    cells.generateMipmaps = false; cells.unpackAlignment = 1; cells.needsUpdate = true;
    const mat = new THREE.ShaderMaterial({
      uniforms: { cells: { value: cells }, palette: { value: paletteTexture(d.options.color_scheme) }, alpha: { value: 1 } },
      vertexShader: MAP_VERTEX, fragmentShader: MAP_FRAGMENT, transparent: true, depthWrite: false, side: THREE.DoubleSide,
    });
    const plane = new THREE.Mesh(new THREE.PlaneGeometry(m.w * m.res, m.h * m.res), mat);
    plane.position.set(m.w * m.res / 2, m.h * m.res / 2, 0);
    const origin = new THREE.Group(); origin.add(plane);
    origin.position.set(m.ox, m.oy, 0); origin.rotation.z = m.oyaw;
    const g = new THREE.Group(); g.add(origin);
    g.userData = { cells, mat, version: m.version, scheme: d.options.color_scheme };
    return g;
  });
  const u = e.obj.userData;
  if (u.version !== m.version) {
    if (m.dirty3) { reduceLevels(u.cells.mipmaps, ...m.dirty3); m.dirty3 = null; }
    u.cells.needsUpdate = true; u.version = m.version;
  }
  if (u.scheme !== d.options.color_scheme) {
    u.mat.uniforms.palette.value.dispose();
    u.mat.uniforms.palette.value = paletteTexture(d.options.color_scheme);
    u.scheme = d.options.color_scheme;
  }
  const alpha = Math.max(0, Math.min(1, d.options.alpha));
  u.mat.uniforms.alpha.value = alpha;
  u.mat.transparent = alpha < 1 || d.options.color_scheme === "costmap";
  e.obj.children[0].children[0].renderOrder = d.options.draw_behind ? -2 : -1;
  const p = frame3(info && info.frame ? info.frame : "map");
  e.obj.visible = !!p;
  if (p) setPose(e.obj, p);
}

const MAX_DRAWN_POINTS = 200000;
function updatePoints(slot, d, L) {
  if (!L.points) return;
  const e = slotObject(slot, "points", () => {
    const geo = new THREE.BufferGeometry();
    const mat = new THREE.PointsMaterial({ size: 3, sizeAttenuation: false, vertexColors: true });
    const pts = new THREE.Points(geo, mat); pts.frustumCulled = false;
    return pts;
  });
  viz.expirePoints(d, L);
  const key = L.points.length + ":" + (L.version || 0);
  e.obj.material.size = d.options.size_px || 3;
  e.obj.material.transparent = d.options.alpha < 1;
  if (e.drawn === key) return;
  e.drawn = key;
  let total = 0;
  for (const s of L.points) total += s.n;
  const step = Math.max(1, Math.ceil(total / MAX_DRAWN_POINTS));  // decimated for drawing
  const n = Math.ceil(total / step), geo = e.obj.geometry;
  if (!e.cap || e.cap < n) {  // buffers grow, then are rewritten in place (no re-allocation per scan)
    e.cap = Math.max(n, 1024);
    e.pos = new THREE.BufferAttribute(new Float32Array(e.cap * 3), 3).setUsage(THREE.DynamicDrawUsage);
    e.rgb = new THREE.BufferAttribute(new Uint8Array(e.cap * 4), 4, true).setUsage(THREE.DynamicDrawUsage);
    geo.setAttribute("position", e.pos); geo.setAttribute("color", e.rgb);
  }
  const pos = e.pos.array, rgb = e.rgb.array;
  let k = 0, idx = 0;
  for (const s of L.points) {
    for (let i = 0; i < s.n; i++, idx++) {
      if (idx % step) continue;
      const a = i * s.stride;
      pos[3 * k] = s.xyz[a]; pos[3 * k + 1] = s.xyz[a + 1]; pos[3 * k + 2] = s.stride === 3 ? s.xyz[a + 2] : 0;
      rgb[4 * k] = s.rgba[4 * i]; rgb[4 * k + 1] = s.rgba[4 * i + 1]; rgb[4 * k + 2] = s.rgba[4 * i + 2]; rgb[4 * k + 3] = s.rgba[4 * i + 3];
      k++;
    }
  }
  e.pos.clearUpdateRanges(); e.pos.addUpdateRange(0, 3 * k); e.pos.needsUpdate = true;
  e.rgb.clearUpdateRanges(); e.rgb.addUpdateRange(0, 4 * k); e.rgb.needsUpdate = true;
  geo.setDrawRange(0, k);
  e.obj.userData.count = k;
}

// URDF mesh visuals: STL (in the URDF material's colour) and COLLADA (its own materials),
// fetched from the dashboard's /mesh/<visual index> (with the page's token: viz.withToken),
// the files of the loaded model only
viz.meshes = { loaded: 0, failed: 0 };
function loadMesh(index, geometry, rgba, alpha) {
  const holder = new THREE.Group();
  holder.scale.set(...geometry.scale);
  const url = viz.withToken(`mesh/${index}`), name = geometry.filename.toLowerCase();
  const a = rgba[3] * alpha;
  const done = (obj) => { holder.add(obj); viz.meshes.loaded += 1; requestDraw(); };
  const fail = (err) => { viz.meshes.failed += 1; console.warn("mesh", geometry.filename, err); };
  if (name.endsWith(".stl")) {
    new STLLoader().load(url, (geo) => {
      geo.computeVertexNormals();
      done(new THREE.Mesh(geo, new THREE.MeshLambertMaterial({ color: new THREE.Color(rgba[0], rgba[1], rgba[2]), transparent: a < 1, opacity: a })));
    }, undefined, fail);
  } else if (name.endsWith(".dae")) {
    new ColladaLoader().load(url, (collada) => {
      // the loader turns Z_UP files to three's y-up; ROS is z-up: undo it (and turn y-up files)
      collada.scene.rotation.set(collada.scene.rotation.x !== 0 ? 0 : Math.PI / 2, 0, 0);
      done(collada.scene);
    }, undefined, fail);
  } else fail("unsupported mesh format");
  return holder;
}

function makeShape(geometry, rgba, alpha, index) {
  let geo;
  if (geometry.type === "mesh") return loadMesh(index, geometry, rgba, alpha);
  if (geometry.type === "box") geo = new THREE.BoxGeometry(...geometry.size);
  else if (geometry.type === "cylinder") {
    geo = new THREE.CylinderGeometry(geometry.radius, geometry.radius, geometry.length, 24);
    geo.rotateX(Math.PI / 2);  // three's cylinders run along y, URDF's along z
  } else if (geometry.type === "sphere") geo = new THREE.SphereGeometry(geometry.radius, 20, 14);
  else return null;
  const a = rgba[3] * alpha;
  const mat = new THREE.MeshLambertMaterial({ color: new THREE.Color(rgba[0], rgba[1], rgba[2]), transparent: a < 1, opacity: a });
  return new THREE.Mesh(geo, mat);
}
function updateRobot(slot, d) {
  const s = data.state;
  if (!s || !s.robot3d) return;
  const key = "robot " + JSON.stringify(s.robot3d) + d.options.alpha;
  const e = slotObject(slot, key, () => {
    const g = new THREE.Group();
    for (const [i, v] of s.robot3d.entries()) {
      const mesh = makeShape(v.geometry, v.rgba, d.options.alpha, i);
      if (!mesh) continue;
      const link = new THREE.Group(); link.userData.link = v.link; link.name = v.link;
      setPose(mesh, v.origin); link.add(mesh); g.add(link);
    }
    return g;
  });
  for (const link of e.obj.children) {
    const p = frame3(link.userData.link);
    link.visible = !!p;
    if (p) setPose(link, p);
  }
}

const AXIS_COLOURS = [0xe62828, 0x28c828, 0x2850e6];
function updateTf(slot, d) {
  const s = data.state;
  if (!s || !s.frames3) return;
  const names = Object.keys(s.frames3).sort();
  const len = 0.3 * d.options.scale;
  const e = slotObject(slot, "tf " + names.join(",") + len, () => {
    const g = new THREE.Group();
    for (const name of names) {
      const pts = [0, 0, 0, len, 0, 0, 0, 0, 0, 0, len, 0, 0, 0, 0, 0, 0, len], cols = [];
      for (const c of AXIS_COLOURS) { const cc = new THREE.Color(c); cols.push(cc.r, cc.g, cc.b, cc.r, cc.g, cc.b); }
      const geo = new THREE.BufferGeometry();
      geo.setAttribute("position", new THREE.Float32BufferAttribute(pts, 3));
      geo.setAttribute("color", new THREE.Float32BufferAttribute(cols, 3));
      const axes = new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false }));
      axes.renderOrder = 10; axes.userData.frame = name; g.add(axes);
    }
    return g;
  });
  e.obj.visible = d.options.show_axes;
  for (const axes of e.obj.children) setPose(axes, frame3(axes.userData.frame));
  if (d.options.show_names) tfLabels.push(...names.map((n) => [n, s.frames3[n]]));
}

export function arrowMesh(len, colour, alpha) {
  const shaft = len * 0.77, head = len - shaft, r = Math.max(0.01, len * 0.025);
  const mat = new THREE.MeshLambertMaterial({ color: colour, transparent: alpha < 1, opacity: alpha });
  const a = new THREE.CylinderGeometry(r, r, shaft, 10); a.rotateZ(-Math.PI / 2); a.translate(shaft / 2, 0, 0);
  const b = new THREE.ConeGeometry(r * 2.5, head, 12); b.rotateZ(-Math.PI / 2); b.translate(shaft + head / 2, 0, 0);
  const g = new THREE.Group(); g.add(new THREE.Mesh(a, mat), new THREE.Mesh(b, mat));
  return g;
}
function updatePoses(slot, d, L) {
  const p = L.poses;
  if (!p) return;
  const o = d.options, key = `poses ${p.length} ${o.length} ${o.color} ${o.alpha}`;
  const e = slotObject(slot, key, () => {
    const g = new THREE.Group();
    for (let i = 0; i < p.length; i += 3) g.add(arrowMesh(o.length, col(o.color), o.alpha));
    return g;
  });
  const q = L.poses3;  // full poses: the arrow at its height, fully oriented
  e.obj.children.forEach((a, j) => {
    if (q) { a.position.set(q[7 * j], q[7 * j + 1], q[7 * j + 2]); a.quaternion.set(q[7 * j + 3], q[7 * j + 4], q[7 * j + 5], q[7 * j + 6]); }
    else { a.position.set(p[3 * j], p[3 * j + 1], 0.02); a.rotation.set(0, 0, p[3 * j + 2]); }
  });
}
function updatePath(slot, d, L) {
  const p = L.path;
  if (!p) return;
  const e = slotObject(slot, "path " + d.options.color, () => new THREE.Line(new THREE.BufferGeometry(),
    new THREE.LineBasicMaterial({ color: col(d.options.color), transparent: true, opacity: d.options.alpha })));
  if (e.path === p) return;
  e.path = p;
  const q = L.path3, pts = new Float32Array(p.length / 2 * 3);
  for (let i = 0, k = 0; i < p.length; i += 2, k += 3) {
    pts[k] = p[i]; pts[k + 1] = p[i + 1]; pts[k + 2] = q ? q[k + 2] : 0.03;
  }
  e.obj.geometry.setAttribute("position", new THREE.BufferAttribute(pts, 3));
  e.obj.geometry.computeBoundingSphere();
}
function updateMarkers(slot, L) {
  if (!L.markers) return;
  const e = slotObject(slot, "markers", () => new THREE.Group());
  if (e.items === L.markers) return;
  e.items = L.markers;
  if (L.markers3d) {  // Marker / MarkerArray: each (ns, id) in full 3D, rebuilt only when it changed
    const old = e.byId || new Map(), next = new Map();
    for (const m of L.markers3d) {
      const id = m.ns + "/" + m.id, shape = markerShapeKey(m);
      let it = old.get(id);
      if (it && it.shape !== shape) { e.obj.remove(it.obj); dispose(it.obj); it = null; }
      if (!it) {
        const obj = buildMarker(m);
        if (!obj) continue;
        it = { shape, obj }; e.obj.add(obj);
      }
      old.delete(id);
      setPose(it.obj, m.pose);
      next.set(id, it);
    }
    for (const it of old.values()) { e.obj.remove(it.obj); dispose(it.obj); }  // deleted / expired
    e.byId = next;
    return;
  }
  for (const c of [...e.obj.children]) { e.obj.remove(c); dispose(c); }
  for (const m of L.markers) {
    const c = new THREE.Color(m.rgba[0], m.rgba[1], m.rgba[2]), a = m.rgba[3];
    const v3 = m.points.map(([x, y]) => new THREE.Vector3(x, y, 0.04));
    if (m.shape === "polygon" && v3.length > 2) {
      const shape = new THREE.Shape(m.points.map(([x, y]) => new THREE.Vector2(x, y)));
      const fill = new THREE.Mesh(new THREE.ShapeGeometry(shape), new THREE.MeshBasicMaterial({ color: c, transparent: true, opacity: a * 0.5, side: THREE.DoubleSide, depthWrite: false }));
      fill.position.z = 0.04; e.obj.add(fill);
      e.obj.add(new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(v3), new THREE.LineBasicMaterial({ color: c })));
    } else if (m.shape === "polyline") {
      e.obj.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(v3), new THREE.LineBasicMaterial({ color: c })));
    } else if (m.shape === "lines") {
      e.obj.add(new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(v3), new THREE.LineBasicMaterial({ color: c })));
    } else if (m.shape === "points") {
      e.obj.add(new THREE.Points(new THREE.BufferGeometry().setFromPoints(v3), new THREE.PointsMaterial({ color: c, size: Math.max(m.size, 0.02) })));
    } else if (m.shape === "arrow") {
      const ar = arrowMesh(m.length, c, a); ar.position.copy(v3[0]); ar.rotation.z = m.yaw; e.obj.add(ar);
    }
  }
}

// the TF names to label (view3d.js places them)
export let tfLabels = [];

export function updateScene() {
  for (const o of objects.values()) o.seen = false;
  tfLabels = [];
  const cfg = data.config;
  if (cfg) {
    cfg.displays.forEach((d, slot) => {
      if (!d.enabled) return;
      const L = data.layers[slot] || {};
      const info = data.state && data.state.displays ? data.state.displays[slot] : null;
      switch (d.kind) {
        case "grid": updateGrid(slot, d); break;
        case "map": updateMap(slot, d, L, info); break;
        case "laser_scan": case "point_cloud2": updatePoints(slot, d, L); break;
        case "robot_model": updateRobot(slot, d); break;
        case "tf": updateTf(slot, d); break;
        case "odometry": case "pose": case "pose_array": updatePoses(slot, d, L); break;
        case "path": updatePath(slot, d, L); break;
        case "marker": case "marker_array": case "pose_with_covariance": case "polygon": updateMarkers(slot, L); break;
        default: break;
      }
    });
  }
  for (const [slot, o] of objects) if (!o.seen) { scene.remove(o.obj); dispose(o.obj); objects.delete(slot); }
}
