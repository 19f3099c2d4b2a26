// roverlab dashboard: visualization_msgs/Marker in the 3D view, as rviz's marker display
// draws them. Each marker comes as the bridge's marker_3d() gives it: type, pose in the
// fixed frame (set on the returned object by the caller), scale, colour, points / colours
// in the marker's own frame, text. Lines have their width in metres (three's Line2).
import * as THREE from "three";
import { Line2 } from "./vendor/three/addons/lines/Line2.js";
import { LineGeometry } from "./vendor/three/addons/lines/LineGeometry.js";
import { LineMaterial } from "./vendor/three/addons/lines/LineMaterial.js";
import { LineSegments2 } from "./vendor/three/addons/lines/LineSegments2.js";
import { LineSegmentsGeometry } from "./vendor/three/addons/lines/LineSegmentsGeometry.js";

export const MARKER = { ARROW: 0, CUBE: 1, SPHERE: 2, CYLINDER: 3, LINE_STRIP: 4, LINE_LIST: 5, CUBE_LIST: 6,
                        SPHERE_LIST: 7, POINTS: 8, TEXT_VIEW_FACING: 9, MESH_RESOURCE: 10, TRIANGLE_LIST: 11 };

const lineMaterials = new Set();  // their resolution follows the canvas
export function setLineResolution(w, h) {
  for (const m of lineMaterials) m.resolution.set(w, h);
}

// everything but the pose: a marker that only moved keeps its objects
export function markerShapeKey(m) {
  return JSON.stringify([m.type, m.scale, m.rgba, m.points || null, m.colors || null, m.text || null]);
}

function material(rgba, opts = {}) {
  const a = rgba[3];
  return new THREE.MeshLambertMaterial({ color: new THREE.Color(rgba[0], rgba[1], rgba[2]), transparent: a < 1,
                                         opacity: a, depthWrite: a >= 1, ...opts });
}

function unitGeometry(type) {
  if (type === MARKER.CUBE || type === MARKER.CUBE_LIST) return new THREE.BoxGeometry(1, 1, 1);
  if (type === MARKER.SPHERE || type === MARKER.SPHERE_LIST) return new THREE.SphereGeometry(0.5, 20, 14);
  const g = new THREE.CylinderGeometry(0.5, 0.5, 1, 24);
  g.rotateX(Math.PI / 2);  // three's cylinders run along y, rviz's along z
  return g;
}

// an arrow along +x from the origin: shaft (length, diameter), head (length, diameter)
function arrow(shaftLen, shaftDia, headLen, headDia, rgba) {
  const mat = material(rgba), g = new THREE.Group();
  if (shaftLen > 0) {
    const shaft = new THREE.CylinderGeometry(shaftDia / 2, shaftDia / 2, shaftLen, 16);
    shaft.rotateZ(-Math.PI / 2); shaft.translate(shaftLen / 2, 0, 0);
    g.add(new THREE.Mesh(shaft, mat));
  }
  const head = new THREE.ConeGeometry(headDia / 2, headLen, 20);
  head.rotateZ(-Math.PI / 2); head.translate(Math.max(shaftLen, 0) + headLen / 2, 0, 0);
  g.add(new THREE.Mesh(head, mat));
  return g;
}

function arrowMarker(m) {
  const [sx, sy, sz] = m.scale, pts = m.points || [];
  if (pts.length >= 2) {  // from points[0] to points[1]: shaft diameter x, head diameter y, head length z
    const a = new THREE.Vector3(...pts[0]), b = new THREE.Vector3(...pts[1]);
    const dist = a.distanceTo(b);
    if (dist <= 0) return null;
    const headLen = sz > 0 ? Math.min(sz, dist) : 0.23 * dist;
    const g = arrow(dist - headLen, sx, headLen, sy, m.rgba);
    g.position.copy(a);
    g.quaternion.setFromUnitVectors(new THREE.Vector3(1, 0, 0), b.clone().sub(a).normalize());
    const holder = new THREE.Group(); holder.add(g);
    return holder;
  }
  // along the pose's x: length scale.x, width scale.y, height scale.z (head twice the shaft)
  const g = arrow(0.77, 1, 0.23, 2, m.rgba);
  g.scale.set(sx, sy, sz);
  const holder = new THREE.Group(); holder.add(g);
  return holder;
}

function colourArray(m, n, alphaOut) {
  const out = new Float32Array(n * 3);
  let alpha = 0;
  for (let i = 0; i < n; i++) {
    const c = m.colors ? m.colors[i] : m.rgba;
    out[3 * i] = c[0]; out[3 * i + 1] = c[1]; out[3 * i + 2] = c[2]; alpha += c[3];
  }
  alphaOut.a = n ? alpha / n : m.rgba[3];
  return out;
}

function lineMarker(m) {
  const pts = m.points || [];
  const list = m.type === MARKER.LINE_LIST, n = list ? pts.length - (pts.length % 2) : pts.length;
  if (n < 2) return null;
  const pos = new Float32Array(n * 3);
  for (let i = 0; i < n; i++) pos.set(pts[i], 3 * i);
  const alpha = {}, colours = colourArray(m, n, alpha);
  const mat = new LineMaterial({ linewidth: Math.max(m.scale[0], 1e-4), worldUnits: true, vertexColors: true,
                                 transparent: alpha.a < 1, opacity: alpha.a });
  lineMaterials.add(mat);
  mat.addEventListener("dispose", () => lineMaterials.delete(mat));
  let line;
  if (list) {
    const geo = new LineSegmentsGeometry(); geo.setPositions(pos); geo.setColors(colours);
    line = new LineSegments2(geo, mat);
  } else {
    const geo = new LineGeometry(); geo.setPositions(pos); geo.setColors(colours);
    line = new Line2(geo, mat);
  }
  line.computeLineDistances();
  const holder = new THREE.Group(); holder.add(line);
  return holder;
}

function pointsMarker(m) {
  const pts = m.points || [];
  if (!pts.length) return null;
  const geo = new THREE.BufferGeometry();
  geo.setAttribute("position", new THREE.Float32BufferAttribute(pts.flat(), 3));
  const alpha = {};
  geo.setAttribute("color", new THREE.Float32BufferAttribute(colourArray(m, pts.length, alpha), 3));
  const mat = new THREE.PointsMaterial({ size: Math.max(m.scale[0], m.scale[1], 1e-3), sizeAttenuation: true,
                                         vertexColors: true, transparent: alpha.a < 1, opacity: alpha.a });
  const p = new THREE.Points(geo, mat); p.frustumCulled = false;
  return p;
}

function listMarker(m) {  // CUBE_LIST / SPHERE_LIST: one instance per point, scale each one's size
  const pts = m.points || [];
  if (!pts.length) return null;
  const mesh = new THREE.InstancedMesh(unitGeometry(m.type), material([1, 1, 1, m.rgba[3]]), pts.length);
  const mtx = new THREE.Matrix4(), c = new THREE.Color();
  for (let i = 0; i < pts.length; i++) {
    mtx.makeScale(...m.scale).setPosition(...pts[i]);
    mesh.setMatrixAt(i, mtx);
    const k = m.colors ? m.colors[i] : m.rgba;
    mesh.setColorAt(i, c.setRGB(k[0], k[1], k[2]));
  }
  mesh.frustumCulled = false;
  return mesh;
}

function triangleMarker(m) {
  const pts = m.points || [], n = pts.length - (pts.length % 3);
  if (n < 3) return null;
  const geo = new THREE.BufferGeometry();
  geo.setAttribute("position", new THREE.Float32BufferAttribute(pts.slice(0, n).flat(), 3));
  let mat;
  if (m.colors && m.colors.length >= n) {
    const alpha = {};
    geo.setAttribute("color", new THREE.Float32BufferAttribute(colourArray(m, n, alpha), 3));
    mat = material([1, 1, 1, alpha.a], { vertexColors: true, side: THREE.DoubleSide });
  } else mat = material(m.rgba, { side: THREE.DoubleSide });
  geo.computeVertexNormals();
  const mesh = new THREE.Mesh(geo, mat);
  mesh.scale.set(...m.scale);
  return mesh;
}

function textMarker(m) {  // TEXT_VIEW_FACING: a sprite, scale.z the height of a capital letter
  const text = m.text || "";
  if (!text) return null;
  const px = 64, lines = text.split("\n"), cv = document.createElement("canvas"), g = cv.getContext("2d");
  g.font = `${px}px sans-serif`;
  const w = Math.max(...lines.map((l) => g.measureText(l).width), 1);
  cv.width = Math.ceil(w) + 8; cv.height = Math.ceil(lines.length * px * 1.2) + 8;
  g.font = `${px}px sans-serif`; g.textBaseline = "top"; g.textAlign = "center";
  g.fillStyle = `rgb(${m.rgba.slice(0, 3).map((v) => Math.round(v * 255)).join(",")})`;
  lines.forEach((l, i) => g.fillText(l, cv.width / 2, 4 + i * px * 1.2));
  const tex = new THREE.CanvasTexture(cv);
  tex.colorSpace = THREE.LinearSRGBColorSpace;
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: tex, transparent: true, opacity: m.rgba[3], depthWrite: false }));
  const h = m.scale[2] * cv.height / (px * 0.72);  // a capital is ~0.72 of the font size
  sprite.scale.set(h * cv.width / cv.height, h, 1);
  sprite.userData.text = text;
  return sprite;
}

// the three.js object of one marker (null: nothing to draw / unsupported)
export function buildMarker(m) {
  switch (m.type) {
    case MARKER.ARROW: return arrowMarker(m);
    case MARKER.CUBE: case MARKER.SPHERE: case MARKER.CYLINDER: {
      const mesh = new THREE.Mesh(unitGeometry(m.type), material(m.rgba));
      mesh.scale.set(...m.scale.map((v) => Math.max(v, 1e-6)));
      const holder = new THREE.Group(); holder.add(mesh);
      return holder;
    }
    case MARKER.LINE_STRIP: case MARKER.LINE_LIST: return lineMarker(m);
    case MARKER.POINTS: return pointsMarker(m);
    case MARKER.CUBE_LIST: case MARKER.SPHERE_LIST: return listMarker(m);
    case MARKER.TRIANGLE_LIST: return triangleMarker(m);
    case MARKER.TEXT_VIEW_FACING: return textMarker(m);
    default: return null;  // MESH_RESOURCE: not drawn
  }
}
