// The report's 3D view: a small WebGL 1 viewer written for mrtmap's report (no library, works
// offline). It reads the room from <script id="view3d-data"> (parts with per-vertex colours, the
// thermal cloud, the MRT grids) and the marked points and globes from <script id="view3d-marks">.
// Left drag orbits, right drag (or shift + drag) pans, the wheel zooms; hovering or clicking a
// surface names it. Walls and ceiling facing the camera are culled, so the room is seen from
// outside like a doll's house.
(function () {
  "use strict";
  const $ = (id) => document.getElementById(id);
  const data = JSON.parse($("view3d-data").textContent);
  const marks = JSON.parse($("view3d-marks").textContent).concat(data.globes || []);
  const canvas = $("view3d");
  const info = $("view3d-info");
  const gl = canvas.getContext("webgl", { antialias: true, preserveDrawingBuffer: true });
  if (!gl) {
    info.textContent = "This browser has no WebGL: the 3D view cannot be drawn.";
    return;
  }
  // report.html#3d shows the view alone; #3d&pick=FX,FY also names what lies at that fraction
  // of the canvas (as a click there would), for checks in a headless browser; &show= sets layers.
  const hash = new URLSearchParams(location.hash.slice(1));
  if (hash.has("3d")) document.body.classList.add("view3d-full");

  const VS = "attribute vec3 p; attribute vec3 c; attribute vec3 n; uniform mat4 m;" +
    "uniform float ps; uniform float lit; varying vec3 vc; void main() {" +
    " gl_Position = m * vec4(p, 1.0); gl_PointSize = ps;" +
    " float s = 0.72 + 0.28 * abs(dot(normalize(n + vec3(1e-6)), normalize(vec3(0.35, 0.55, 0.76))));" +
    " vc = c * mix(1.0, s, lit); }";
  const FS = "precision mediump float; varying vec3 vc; uniform float a;" +
    " void main() { gl_FragColor = vec4(vc, a); }";
  function shader(type, src) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    return s;
  }
  const prog = gl.createProgram();
  gl.attachShader(prog, shader(gl.VERTEX_SHADER, VS));
  gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, FS));
  gl.linkProgram(prog);
  gl.useProgram(prog);
  const loc = {
    p: gl.getAttribLocation(prog, "p"), c: gl.getAttribLocation(prog, "c"),
    n: gl.getAttribLocation(prog, "n"), m: gl.getUniformLocation(prog, "m"),
    ps: gl.getUniformLocation(prog, "ps"), lit: gl.getUniformLocation(prog, "lit"),
    a: gl.getUniformLocation(prog, "a"),
  };

  // A drawable: positions, colours and normals, non-indexed.
  function drawable(pos, col, nor, mode) {
    const mk = (arr) => {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(arr), gl.STATIC_DRAW);
      return b;
    };
    return { p: mk(pos), c: mk(col), n: mk(nor), count: pos.length / 3, mode: mode };
  }

  // Parts by layer, as triangles with flat normals; each part keeps its triangles for picking.
  const layerOf = { surface: "surfaces", feature: "features", furniture: "furniture" };
  const geo = { surfaces: [[], [], []], features: [[], [], []], furniture: [[], [], []] };
  const pick = [];
  for (const part of data.parts) {
    const g = geo[layerOf[part.role]];
    const P = part.p, C = part.c, I = part.i;
    const tris = [];
    for (let k = 0; k < I.length; k += 3) {
      const v = [I[k], I[k + 1], I[k + 2]].map((i) => [P[3 * i], P[3 * i + 1], P[3 * i + 2]]);
      const e1 = sub(v[1], v[0]), e2 = sub(v[2], v[0]);
      const nn = cross(e1, e2);
      for (let j = 0; j < 3; j++) {
        const i = I[k + j];
        g[0].push(P[3 * i], P[3 * i + 1], P[3 * i + 2]);
        g[1].push(C[3 * i] / 255, C[3 * i + 1] / 255, C[3 * i + 2] / 255);
        g[2].push(nn[0], nn[1], nn[2]);
      }
      tris.push([v[0], v[1], v[2], nn]);
    }
    pick.push({ part: part, tris: tris, layer: layerOf[part.role] });
  }
  const layers = {};
  for (const name in geo) {
    if (geo[name][0].length) layers[name] = drawable(geo[name][0], geo[name][1], geo[name][2], gl.TRIANGLES);
  }
  if (data.cloud && data.cloud.p.length) {
    const n = new Array(data.cloud.p.length).fill(0);
    layers.cloud = drawable(data.cloud.p, data.cloud.c.map((x) => x / 255), n, gl.POINTS);
  }
  // Each MRT grid as translucent cells around its nodes.
  data.grids.forEach((grid, k) => {
    const pos = [], col = [], nor = [];
    const hu = grid.cell[0] / 2, hv = grid.cell[1] / 2, u = grid.u, v = grid.v;
    for (const nd of grid.n) {
      const q = (a, b) => [0, 1, 2].map((j) => nd[j] + a * u[j] + b * v[j]);
      const corners = [q(-hu, -hv), q(hu, -hv), q(hu, hv), q(-hu, -hv), q(hu, hv), q(-hu, hv)];
      for (const c of corners) {
        pos.push(c[0], c[1], c[2]);
        col.push(nd[4] / 255, nd[5] / 255, nd[6] / 255);
        nor.push(0, 0, 0);
      }
    }
    layers["grid" + k] = drawable(pos, col, nor, gl.TRIANGLES);
  });
  // The sunlit patch: orange cells on the floor where the beam reaches a person.
  if (data.sun && data.sun.cells.length) {
    const pos = [], col = [], nor = [];
    const hu = data.sun.cell[0] / 2, hv = data.sun.cell[1] / 2, u = data.sun.u, v = data.sun.v;
    for (const nd of data.sun.cells) {
      const q = (a, b) => [0, 1, 2].map((j) => nd[j] + a * u[j] + b * v[j]);
      for (const c of [q(-hu, -hv), q(hu, -hv), q(hu, hv), q(-hu, -hv), q(hu, hv), q(-hu, hv)]) {
        pos.push(c[0], c[1], c[2]);
        col.push(1, 0.55, 0);
        nor.push(0, 0, 0);
      }
    }
    layers.sun = drawable(pos, col, nor, gl.TRIANGLES);
  }
  if (marks.length) {
    const pos = [], col = [], nor = [];
    for (const mk of marks) {
      pos.push(mk.xyz[0], mk.xyz[1], mk.xyz[2]);
      const c = mk.kind === "globe" ? [0.1, 0.1, 0.1] : [0.15, 0.3, 0.55];
      col.push(c[0], c[1], c[2]);
      nor.push(0, 0, 0);
    }
    layers.marks = drawable(pos, col, nor, gl.POINTS);
  }

  // Which layers show: the buttons toggle them.
  const shown = { surfaces: true, features: true, furniture: true, cloud: false, marks: true, sun: true };
  data.grids.forEach((_, k) => { shown["grid" + k] = k === 0; });
  // #3d&show=cloud,-grid0 turns layers on (or, with "-", off) from the address.
  for (const w of (hash.get("show") || "").split(",").filter(Boolean)) {
    if (w[0] === "-") shown[w.slice(1)] = false; else shown[w] = true;
  }
  document.querySelectorAll("#view3d-buttons button[data-layer]").forEach((b) => {
    const name = b.dataset.layer;
    if (!layers[name]) { b.disabled = true; return; }
    b.classList.toggle("on", !!shown[name]);
    b.addEventListener("click", () => {
      shown[name] = !shown[name];
      b.classList.toggle("on", shown[name]);
      updateBars();
      draw();
    });
  });
  const full = $("view3d-fullscreen");
  if (full) full.addEventListener("click", () => { document.body.classList.toggle("view3d-full"); resize(); });

  // The camera: orbit about the room's centre, z up.
  const cam = { yaw: -2.2, pitch: 0.62, dist: 1.35 * data.size, target: data.centre.slice() };
  // Start facing the wall whose feature stands out most (its outward normal is `look`), from a
  // little to one side.
  if (data.look) cam.yaw = Math.atan2(-data.look[1], -data.look[0]) + 0.5;
  function eye() {
    const cp = Math.cos(cam.pitch);
    return [cam.target[0] + cam.dist * cp * Math.cos(cam.yaw),
      cam.target[1] + cam.dist * cp * Math.sin(cam.yaw),
      cam.target[2] + cam.dist * Math.sin(cam.pitch)];
  }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function norm(a) { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }
  function basis() {
    const f = norm(sub(cam.target, eye()));
    const r = norm(cross(f, [0, 0, 1]));
    return { f: f, r: r, u: cross(r, f) };
  }
  function matrix() {
    const e = eye(), b = basis();
    const aspect = canvas.width / Math.max(1, canvas.height);
    const t = 1 / Math.tan((45 * Math.PI) / 360);
    const near = cam.dist * 0.02, far = cam.dist * 20;
    const view = [b.r[0], b.u[0], -b.f[0], 0, b.r[1], b.u[1], -b.f[1], 0, b.r[2], b.u[2], -b.f[2], 0,
      -dot(b.r, e), -dot(b.u, e), dot(b.f, e), 1];
    const proj = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0,
      (2 * far * near) / (near - far), 0];
    const m = new Array(16).fill(0);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) m[c * 4 + r] += proj[k * 4 + r] * view[c * 4 + k];
    return m;
  }
  function project(p, m) {
    const x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
    const y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
    const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
    if (w <= 0) return null;
    return [(x / w + 1) * 0.5 * canvas.clientWidth, (1 - y / w) * 0.5 * canvas.clientHeight];
  }

  function bind(d) {
    for (const [a, b] of [[loc.p, d.p], [loc.c, d.c], [loc.n, d.n]]) {
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.enableVertexAttribArray(a);
      gl.vertexAttribPointer(a, 3, gl.FLOAT, false, 0, 0);
    }
  }
  function draw() {
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.96, 0.96, 0.95, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const m = matrix();
    gl.uniformMatrix4fv(loc.m, false, m);
    gl.uniform1f(loc.a, 1);
    gl.disable(gl.BLEND);
    gl.depthMask(true);
    const dpr = window.devicePixelRatio || 1;
    for (const name of ["surfaces", "features", "furniture", "cloud"]) {
      const d = layers[name];
      if (!d || !shown[name]) continue;
      // The envelope is wound outward: culling its front faces opens the near walls.
      if (name === "surfaces" || name === "features") { gl.enable(gl.CULL_FACE); gl.cullFace(gl.FRONT); }
      else if (name === "furniture") { gl.enable(gl.CULL_FACE); gl.cullFace(gl.BACK); }
      else gl.disable(gl.CULL_FACE);
      gl.uniform1f(loc.lit, name === "furniture" ? 1 : 0);
      gl.uniform1f(loc.ps, 2.5 * dpr);
      bind(d);
      gl.drawArrays(d.mode, 0, d.count);
    }
    gl.disable(gl.CULL_FACE);
    gl.enable(gl.BLEND);
    // The canvas stays opaque (alpha untouched), so the page's white does not wash the colours out.
    gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ZERO, gl.ONE);
    gl.depthMask(false);
    gl.uniform1f(loc.a, 0.6);
    gl.uniform1f(loc.lit, 0);
    data.grids.forEach((_, k) => {
      const d = layers["grid" + k];
      if (d && shown["grid" + k]) { bind(d); gl.drawArrays(d.mode, 0, d.count); }
    });
    if (layers.sun && shown.sun) { bind(layers.sun); gl.drawArrays(layers.sun.mode, 0, layers.sun.count); }
    gl.depthMask(true);
    // Points and globes last, over everything, as their labels are.
    if (layers.marks && shown.marks) {
      gl.disable(gl.BLEND);
      gl.disable(gl.DEPTH_TEST);
      gl.uniform1f(loc.a, 1);
      gl.uniform1f(loc.ps, 11 * dpr);
      bind(layers.marks);
      gl.drawArrays(layers.marks.mode, 0, layers.marks.count);
      gl.enable(gl.DEPTH_TEST);
    }
    placeLabels(m);
  }

  // Labels of marked points and globes, placed over the canvas.
  const labelBox = $("view3d-labels");
  const labels = marks.map((mk) => {
    const el = document.createElement("span");
    el.className = "view3d-label";
    el.textContent = mk.text;
    labelBox.appendChild(el);
    return el;
  });
  function placeLabels(m) {
    marks.forEach((mk, k) => {
      const s = shown.marks ? project(mk.xyz, m) : null;
      labels[k].style.display = s ? "block" : "none";
      if (s) { labels[k].style.left = s[0] + 8 + "px"; labels[k].style.top = s[1] - 8 + "px"; }
    });
  }

  // Colour bars: the surfaces' and, when a grid shows, its own.
  function bar(el, range, stops, title) {
    el.innerHTML = "";
    const t = document.createElement("div");
    t.textContent = title;
    const g = document.createElement("div");
    g.className = "view3d-gradient";
    g.style.background = "linear-gradient(to right," + stops.join(",") + ")";
    const l = document.createElement("div");
    l.className = "view3d-ticks";
    const fmt = (x) => x.toFixed(1);
    l.innerHTML = "<span>" + fmt(range[0]) + "</span><span>" + fmt((range[0] + range[1]) / 2) +
      "</span><span>" + fmt(range[1]) + " °C</span>";
    el.append(t, g, l);
  }
  function updateBars() {
    bar($("view3d-bar"), data.range, data.bar, "Surface temperature");
    const k = data.grids.findIndex((_, i) => shown["grid" + i]);
    const gb = $("view3d-gridbar");
    if (k >= 0) {
      gb.style.display = "block";
      bar(gb, data.grids[k].range, data.grids[k].bar, "MRT at " + data.grids[k].height.toFixed(2) + " m");
    } else gb.style.display = "none";
  }

  // Picking: the nearest visible triangle under the cursor.
  function rayAt(x, y) {
    const b = basis();
    const t = Math.tan((45 * Math.PI) / 360);
    const aspect = canvas.clientWidth / Math.max(1, canvas.clientHeight);
    const sx = ((2 * x) / canvas.clientWidth - 1) * t * aspect, sy = (1 - (2 * y) / canvas.clientHeight) * t;
    return { o: eye(), d: norm([0, 1, 2].map((j) => b.f[j] + sx * b.r[j] + sy * b.u[j])) };
  }
  function hit(ray) {
    let best = null;
    for (const pk of pick) {
      if (!shown[pk.layer]) continue;
      for (const [a, b, c, n] of pk.tris) {
        const facing = dot(ray.d, n);
        // What the culling shows: the envelope's inner side, the furniture's outer side.
        if (pk.layer === "furniture" ? facing >= 0 : facing <= 0) continue;
        const e1 = sub(b, a), e2 = sub(c, a), h = cross(ray.d, e2), det = dot(e1, h);
        if (Math.abs(det) < 1e-12) continue;
        const s = sub(ray.o, a), u = dot(s, h) / det;
        if (u < 0 || u > 1) continue;
        const q = cross(s, e1), v = dot(ray.d, q) / det;
        if (v < 0 || u + v > 1) continue;
        const dist = dot(e2, q) / det;
        if (dist > 1e-6 && (!best || dist < best.dist)) best = { dist: dist, part: pk.part };
      }
    }
    return best;
  }
  function describe(p) {
    let s = p.id + (p.label && p.label !== p.id ? " (" + p.label + ")" : "") + ": " + p.t.toFixed(2) + " °C";
    if (p.std != null) s += " ± " + (p.std < 0.005 ? "< 0.01" : p.std.toFixed(2)) + " K";
    if (p.st != null) s += " radiant; surface " + p.st.toFixed(2) + " °C ± " + p.sst.toFixed(2) + " K (ε " + p.e.toFixed(2) + ")";
    s += "; " + p.area.toFixed(2) + " m²";
    if (p.seen != null) s += "; " + Math.round(100 * p.seen) + " % seen";
    if (p.role === "feature") s += "; on " + p.detail;
    return s;
  }
  function showAt(e) {
    const r = canvas.getBoundingClientRect();
    nameAt(e.clientX - r.left, e.clientY - r.top);
  }
  function nameAt(x, y) {
    const h = hit(rayAt(x, y));
    info.textContent = h ? describe(h.part) : "Hover or click a surface to name it.";
  }

  // Mouse: orbit, pan, zoom.
  let drag = null;
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("mousedown", (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey, moved: false }; });
  window.addEventListener("mouseup", (e) => { if (drag && !drag.moved) showAt(e); drag = null; });
  window.addEventListener("mousemove", (e) => {
    if (!drag) { if (e.target === canvas) showAt(e); return; }
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 2) drag.moved = true;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const b = basis(), k = (cam.dist * 1.2) / canvas.clientHeight;
      for (let j = 0; j < 3; j++) cam.target[j] += (-dx * b.r[j] + dy * b.u[j]) * k;
    } else {
      cam.yaw -= dx * 0.008;
      cam.pitch = Math.max(-1.5, Math.min(1.5, cam.pitch + dy * 0.008));
    }
    draw();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    cam.dist = Math.max(0.2, Math.min(50 * data.size, cam.dist * Math.exp(e.deltaY * 0.001)));
    draw();
  }, { passive: false });

  function resize() {
    const dpr = window.devicePixelRatio || 1;
    canvas.width = Math.round(canvas.clientWidth * dpr);
    canvas.height = Math.round(canvas.clientHeight * dpr);
    draw();
  }
  window.addEventListener("resize", resize);
  updateBars();
  resize();
  canvas.dataset.drawn = "yes";
  const at = (hash.get("pick") || "").split(",").map(Number);
  if (at.length === 2 && at.every(isFinite)) nameAt(at[0] * canvas.clientWidth, at[1] * canvas.clientHeight);
})();
