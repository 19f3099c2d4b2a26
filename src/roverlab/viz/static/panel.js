// roverlab dashboard: the side panels: Global Options, the Displays with their property
// editors (add, remove, rename, options, status), the image panels, the joint sliders and
// the topic list. app.js sets it up on the page's state (window.vizPanel). No build step.
"use strict";
window.vizPanel = ({ $, view, data, send, redraw, requestDraw, configHooks, paintMap }) => {
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
      imageMessage(slot, rows);
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
      // rqt_image_view's empty canvas says why: no topic, no publisher, not an image, ...
      const msg = document.createElement("div"); msg.className = "imgmsg"; msg.dataset.slot = slot;
      msg.textContent = d.topic ? `Waiting for images on ${d.topic}` : "Pick an image topic";
      if (first) { sel.id = "image-topic"; img.id = "camera"; msg.id = "camera-message"; first = false; }
      div.append(row, msg, img); box.appendChild(div);
    });
    if (first) {  // no image display: a picker that makes one
      const sel = document.createElement("select"); sel.id = "image-topic"; sel.className = "image-topic";
      sel.onchange = () => { if (sel.value) send({ type: "image_topic", topic: sel.value }); };
      const row = document.createElement("div"); row.className = "row"; row.append(sel); box.appendChild(row);
    }
    renderImageTopics(data.state ? data.state.image_topics || [] : []);
  }
  // an image display with no picture yet shows its status in the panel instead
  function imageMessage(slot, rows) {
    const d = data.config.displays[slot];
    if (!d || d.kind !== "image") return;
    const msg = document.querySelector(`.imgmsg[data-slot="${slot}"]`);
    const img = document.querySelector(`img[data-slot="${slot}"]`);
    if (!msg || !img || img.classList.contains("shown")) return;
    const bad = rows.filter((r) => r[0] === "warn" || r[0] === "error").map((r) => r[2]);
    if (!d.topic) msg.textContent = "Pick an image topic";
    else if (bad.length) msg.textContent = bad.join("; ");
    else msg.textContent = `Waiting for images on ${d.topic}`;
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
      // live when it has a publisher or messages flow (a publisher the graph does not show yet)
      const live = x.publishers > 0 || x.hz > 0;
      return `<tr class="${live ? "" : "none"}" title="${x.type}: ${x.publishers} publisher(s), ${x.subscribers} subscriber(s)"><td>${x.name}</td><td class="hz">${hz} Hz</td></tr>`;
    });
    t.innerHTML = rows.join("");
  }

  return { onConfig, renderTopics, updateStatus, updateFrameSelects, renderImageTopics, renderJoints };
};
