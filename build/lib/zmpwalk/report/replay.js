// The report's interactive replay (zmpwalk.report.replay): three.js (global THREE), no network.
// window.zmpwalkReplay.setTime(t) sets the time; the page URL's "#t=1.5" opens it paused at 1.5 s and
// "#replay&t=1.5" shows the replay alone.
(function () {
  "use strict";
  var section = document.getElementById("replay");
  var payload = JSON.parse(document.getElementById("replay-data").textContent);
  function bytes(b64) {
    var s = atob(b64), u = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) u[i] = s.charCodeAt(i);
    return u.buffer;
  }
  function floats(b64) { return new Float32Array(bytes(b64)); }
  var F = payload.frames, n = F.count, nb = F.bodies, start = payload.start, end = payload.end;
  var time = floats(F.time), pos = floats(F.position), quat = floats(F.quaternion);
  var base = floats(F.base), zmp = floats(F.zmp), cop = floats(F.cop);
  var state = { t: 0, playing: true, speed: 1, follow: true, last: null };
  var slider = document.getElementById("replay-slider"), label = document.getElementById("replay-time");
  var button = document.getElementById("replay-play"), plot = document.getElementById("replay-plot");
  var view = null;  // the 3D view, once WebGL works

  function frameAt(t) {  // the last frame at or before t (times are float32: 1 µs slack)
    var lo = 0, hi = n - 1;
    while (lo < hi) { var mid = (lo + hi + 1) >> 1; if (time[mid] <= t + 1e-6) lo = mid; else hi = mid - 1; }
    return lo;
  }
  function setTime(t) {
    state.t = Math.min(Math.max(Number(t) || 0, start), end);
    var k = frameAt(state.t);
    slider.value = state.t.toFixed(3);
    label.textContent = "t = " + state.t.toFixed(2) + " s";
    section.setAttribute("data-time", state.t.toFixed(3));
    section.setAttribute("data-frame", String(k));
    section.setAttribute("data-base-x", base[3 * k].toFixed(4));
    section.setAttribute("data-base-y", base[3 * k + 1].toFixed(4));
    if (view) view.show(k);
    drawPlot();
    cursors.forEach(function (cursor) { cursor.show(state.t); });
  }
  function setPlaying(on) {
    state.playing = on; state.last = null;
    button.textContent = on ? "pause" : "play";
  }
  window.zmpwalkReplay = { setTime: setTime, play: function () { setPlaying(true); },
                           pause: function () { setPlaying(false); }, time: function () { return state.t; } };

  // The time plot: reference ZMP and measured CoP, x above and y below; click or drag sets the time.
  var pad = 44;
  function drawPlot() {
    var g = plot.getContext("2d"), w = plot.width, h = plot.height, half = h / 2;
    g.clearRect(0, 0, w, h);
    g.font = "11px sans-serif";
    for (var axis = 0; axis < 2; axis++) {
      var lo = Infinity, hi = -Infinity, k;
      for (k = 0; k < n; k++) {
        [zmp[2 * k + axis], cop[2 * k + axis]].forEach(function (v) {
          if (isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
        });
      }
      if (!(hi > lo)) { lo -= 0.1; hi += 0.1; }
      var top = axis * half + 6, height = half - 14;
      var y = function (v) { return top + height * (1 - (v - lo) / (hi - lo)); };
      g.strokeStyle = "#ccc"; g.strokeRect(pad, top, w - pad - 4, height);
      g.fillStyle = "#555"; g.fillText((axis ? "y" : "x") + " [m]", 4, top + 12);
      g.fillText(hi.toFixed(2), 4, top + 26); g.fillText(lo.toFixed(2), 4, top + height);
      [[zmp, "#1f77b4"], [cop, "#d62728"]].forEach(function (line) {
        g.strokeStyle = line[1]; g.beginPath();
        var pen = false;
        for (var j = 0; j < n; j++) {
          var v = line[0][2 * j + axis], px = pad + (w - pad - 4) * (time[j] - start) / (end - start);
          if (!isFinite(v)) { pen = false; continue; }
          if (pen) g.lineTo(px, y(v)); else g.moveTo(px, y(v));
          pen = true;
        }
        g.stroke();
      });
    }
    var cx = pad + (w - pad - 4) * (state.t - start) / (end - start);
    g.strokeStyle = "#000"; g.lineWidth = 1.5; g.beginPath(); g.moveTo(cx, 0); g.lineTo(cx, h); g.stroke();
    g.lineWidth = 1;
  }
  function plotTime(event) {
    var box = plot.getBoundingClientRect(), x = (event.clientX - box.left) * plot.width / box.width;
    setPlaying(false);
    setTime(start + (end - start) * (x - pad) / (plot.width - pad - 4));
  }
  plot.addEventListener("mousedown", function (e) { plotTime(e); plot.dragging = true; });
  plot.addEventListener("mousemove", function (e) { if (plot.dragging) plotTime(e); });
  window.addEventListener("mouseup", function () { plot.dragging = false; });
  slider.addEventListener("input", function () { setPlaying(false); setTime(slider.value); });
  button.addEventListener("click", function () { setPlaying(!state.playing); });
  document.getElementById("replay-speed").addEventListener("change", function (e) {
    state.speed = Number(e.target.value);
  });
  document.getElementById("replay-follow").addEventListener("change", function (e) {
    state.follow = e.target.checked;
    if (view) view.show(frameAt(state.t));
  });

  // A time cursor on each report figure whose <img> carries data-time-axis (left, right, top, bottom as fractions
  // of the image, t0 and t1 its time limits [s]); clicking on the figure sets the time.
  var cursors = [];
  function cursor(img) {
    var axis = JSON.parse(img.getAttribute("data-time-axis")), holder = document.createElement("div");
    holder.style.cssText = "position:relative;display:inline-block;max-width:100%";
    img.parentNode.insertBefore(holder, img); holder.appendChild(img);
    var line = document.createElement("div");
    line.className = "replay-cursor";
    line.style.cssText = "position:absolute;width:2px;margin-left:-1px;background:#000;opacity:0.7;pointer-events:none;" +
      "top:" + (100 * axis.top) + "%;height:" + (100 * (axis.bottom - axis.top)) + "%";
    holder.appendChild(line);
    img.style.cursor = "crosshair";
    img.addEventListener("click", function (e) {
      var box = img.getBoundingClientRect(), x = (e.clientX - box.left) / box.width;
      if (x < axis.left || x > axis.right) return;
      setPlaying(false);
      setTime(axis.t0 + (axis.t1 - axis.t0) * (x - axis.left) / (axis.right - axis.left));
    });
    return { show: function (t) {
      var x = axis.left + (axis.right - axis.left) * (t - axis.t0) / (axis.t1 - axis.t0);
      line.style.left = (100 * x).toFixed(3) + "%";
      line.setAttribute("data-time", t.toFixed(3));
    } };
  }
  function attachCursors() {  // the figures come after the replay in the page
    cursors = Array.prototype.map.call(document.querySelectorAll("img[data-time-axis]"), cursor);
    cursors.forEach(function (c) { c.show(state.t); });
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", attachCursors);
  else attachCursors();

  function geometry(geom) {
    var s = geom.size, g;
    if (geom.kind === "box") g = new THREE.BoxGeometry(2 * s[0], 2 * s[1], 2 * s[2]);
    else if (geom.kind === "sphere") g = new THREE.SphereGeometry(s[0], 20, 14);
    else if (geom.kind === "ellipsoid") g = new THREE.SphereGeometry(1, 20, 14).scale(s[0], s[1], s[2]);
    else if (geom.kind === "capsule") g = new THREE.CapsuleGeometry(s[0], 2 * s[1], 6, 16).rotateX(Math.PI / 2);
    else if (geom.kind === "cylinder") g = new THREE.CylinderGeometry(s[0], s[0], 2 * s[1], 24).rotateX(Math.PI / 2);
    else {
      g = new THREE.BufferGeometry();
      g.setAttribute("position", new THREE.BufferAttribute(floats(geom.vertices), 3));
      g.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(geom.faces)), 1));
      g.computeVertexNormals();
    }
    return g;
  }
  function sole(corners, z, color, opacity) {
    var shape = new THREE.Shape(corners.map(function (c) { return new THREE.Vector2(c[0], c[1]); }));
    var mesh = new THREE.Mesh(new THREE.ShapeGeometry(shape), new THREE.MeshBasicMaterial(
      { color: color, transparent: true, opacity: opacity, depthWrite: false, side: THREE.DoubleSide }));
    mesh.position.z = z;
    var points = corners.concat([corners[0]]).map(function (c) { return new THREE.Vector3(c[0], c[1], z); });
    var line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(points), new THREE.LineBasicMaterial({ color: color }));
    var group = new THREE.Group(); group.add(mesh); group.add(line);
    return group;
  }
  function disc(color, z) {
    var mesh = new THREE.Mesh(new THREE.CircleGeometry(0.025 * payload.height, 24),
                              new THREE.MeshBasicMaterial({ color: color, depthTest: false }));
    mesh.position.z = z; mesh.renderOrder = 2;
    return mesh;
  }

  function ground(scene) {  // the floor with a 10 cm grid, the planned and the measured footprints
    var H = payload.height, lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
    var prints = payload.footprints.planned.concat(payload.footprints.measured);
    prints.forEach(function (p) { p.corners.forEach(function (c) {
      lo = [Math.min(lo[0], c[0]), Math.min(lo[1], c[1])]; hi = [Math.max(hi[0], c[0]), Math.max(hi[1], c[1])];
    }); });
    if (!prints.length) { lo = [0, 0]; hi = [0, 0]; }
    var centre = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2], span = Math.max(hi[0] - lo[0], hi[1] - lo[1], H) + 2 * H;
    var floor = new THREE.Mesh(new THREE.PlaneGeometry(span, span), new THREE.MeshLambertMaterial({ color: 0xd9dde2 }));
    floor.position.set(centre[0], centre[1], 0); scene.add(floor);
    var grid = new THREE.GridHelper(span, Math.round(span / 0.1), 0xaab0b8, 0xc4c9cf);
    grid.rotation.x = Math.PI / 2; grid.position.set(centre[0], centre[1], 0.0005); scene.add(grid);
    payload.footprints.planned.forEach(function (p) { scene.add(sole(p.corners, 0.001, 0x666666, 0.25)); });
    var landed = payload.footprints.measured.map(function (p) {  // shown from the time the sole landed there
      var print = sole(p.corners, 0.002, 0xd62728, 0.2); print.userData.t = p.t; scene.add(print);
      return print;
    });
    section.setAttribute("data-footprints-planned", String(payload.footprints.planned.length));
    section.setAttribute("data-footprints-measured", String(payload.footprints.measured.length));
    return { centre: centre, landed: landed };
  }
  function robot(scene) {  // a group per body holding its geoms at their local poses
    var bodies = [];
    for (var b = 0; b < nb; b++) { bodies.push(new THREE.Group()); scene.add(bodies[b]); }
    payload.geoms.forEach(function (geom) {
      var c = geom.rgba, material = new THREE.MeshLambertMaterial(
        { color: new THREE.Color(c[0], c[1], c[2]), transparent: c[3] < 1, opacity: c[3] });
      var mesh = new THREE.Mesh(geometry(geom), material);
      mesh.position.set(geom.pos[0], geom.pos[1], geom.pos[2]);
      mesh.quaternion.set(geom.quat[1], geom.quat[2], geom.quat[3], geom.quat[0]);
      bodies[geom.body].add(mesh);
    });
    section.setAttribute("data-geoms", String(payload.geoms.length));
    return bodies;
  }

  function makeView() {
    var box = document.getElementById("replay-view");
    var renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(box.clientWidth, box.clientHeight);
    box.appendChild(renderer.domElement);
    var scene = new THREE.Scene();
    scene.background = new THREE.Color(0xe8ecf0);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 1.6));
    var sun = new THREE.DirectionalLight(0xffffff, 1.4); sun.position.set(2, -3, 5); scene.add(sun);
    var H = payload.height, floor = ground(scene), landed = floor.landed, centre = floor.centre;
    var zmpDisc = disc(0x1f77b4, 0.003), copDisc = disc(0xd62728, 0.004);
    scene.add(zmpDisc); scene.add(copDisc);
    var bodies = robot(scene);
    var camera = new THREE.PerspectiveCamera(40, box.clientWidth / box.clientHeight, 0.01, 100);
    camera.up.set(0, 0, 1);
    var orbit = { azimuth: -1.2, elevation: 0.25, distance: 2.1 * H, target: new THREE.Vector3() };
    var frame = 0;
    function place() {
      if (state.follow) orbit.target.set(base[3 * frame], base[3 * frame + 1], 0.45 * H);
      else orbit.target.set(centre[0], centre[1], 0.45 * H);
      var ce = Math.cos(orbit.elevation), d = orbit.distance;
      camera.position.set(orbit.target.x + d * ce * Math.cos(orbit.azimuth),
                          orbit.target.y + d * ce * Math.sin(orbit.azimuth), orbit.target.z + d * Math.sin(orbit.elevation));
      camera.lookAt(orbit.target);
    }
    var canvas = renderer.domElement, drag = null;
    canvas.addEventListener("mousedown", function (e) { drag = [e.clientX, e.clientY]; });
    window.addEventListener("mouseup", function () { drag = null; });
    window.addEventListener("mousemove", function (e) {
      if (!drag) return;
      orbit.azimuth -= 0.01 * (e.clientX - drag[0]);
      orbit.elevation = Math.min(1.5, Math.max(-0.1, orbit.elevation + 0.01 * (e.clientY - drag[1])));
      drag = [e.clientX, e.clientY];
    });
    canvas.addEventListener("wheel", function (e) {
      e.preventDefault();
      orbit.distance = Math.min(20 * H, Math.max(0.3 * H, orbit.distance * Math.exp(0.001 * e.deltaY)));
    }, { passive: false });
    window.addEventListener("resize", function () {
      renderer.setSize(box.clientWidth, box.clientHeight);
      camera.aspect = box.clientWidth / box.clientHeight; camera.updateProjectionMatrix();
    });
    return {
      show: function (k) {
        frame = k;
        for (var b = 0; b < nb; b++) {
          var i = k * nb + b;
          bodies[b].position.set(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
          bodies[b].quaternion.set(quat[4 * i + 1], quat[4 * i + 2], quat[4 * i + 3], quat[4 * i]);
        }
        zmpDisc.position.x = zmp[2 * k]; zmpDisc.position.y = zmp[2 * k + 1];
        copDisc.visible = isFinite(cop[2 * k]);
        var shown = 0;
        landed.forEach(function (print) { print.visible = print.userData.t <= time[k] + 1e-6; shown += print.visible; });
        section.setAttribute("data-footprints-shown", String(shown));
        if (copDisc.visible) { copDisc.position.x = cop[2 * k]; copDisc.position.y = cop[2 * k + 1]; }
      },
      render: function () { place(); renderer.render(scene, camera); }
    };
  }

  if (/^#replay/.test(window.location.hash)) {  // the replay alone (screenshots)
    Array.prototype.forEach.call(document.body.children, function (child) {
      if (child !== section && child.tagName !== "SCRIPT") child.style.display = "none";
    });
  }
  try {
    if (typeof THREE === "undefined") throw new Error("three.js did not load");
    view = makeView();
    section.setAttribute("data-ready", "yes");
  } catch (error) {
    view = null;
    document.getElementById("replay-view").hidden = true;
    document.getElementById("replay-fallback").hidden = false;
    section.setAttribute("data-ready", "no-webgl");
    section.setAttribute("data-error", String(error && error.message || error));
  }
  var hash = /[#&]t=(-?[0-9.]+)/.exec(window.location.hash);
  if (hash) setPlaying(false);
  setTime(hash ? Number(hash[1]) : start);
  function tick(now) {
    if (state.playing) {
      if (state.last !== null) {
        var t = state.t + state.speed * (now - state.last) / 1000;
        setTime(t > end ? start : t);
      }
      state.last = now;
    }
    if (view) view.render();
    window.requestAnimationFrame(tick);
  }
  window.requestAnimationFrame(tick);
})();
