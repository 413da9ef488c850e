// kestrel station page: draws what kestrel-station sends on its socket and sends the
// operator's goals and holds. The wire format is station/wire.h (binary: map differences and
// images) and station/updates.h (JSON). World frame: z up, metres.
'use strict';

(function () {
  const params = new URLSearchParams(location.search);
  const token = params.get('token') || '';

  // --- the scene -------------------------------------------------------------------------
  const view = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.setPixelRatio(1);
  renderer.setClearColor(0x15181c);
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(55, 1, 0.05, 500);
  camera.up.set(0, 0, 1);
  camera.position.set(-4, -6, 6);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.set(0, 0, 1);
  controls.update();
  // The view follows the map's bounds until the operator turns or moves it.
  let userMoved = false;
  controls.addEventListener('start', () => { userMoved = true; });
  function frameBounds(b) {
    const c = new THREE.Vector3((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
    const r = Math.max(b[3] - b[0], b[4] - b[1], b[5] - b[2], 2);
    controls.target.copy(c);
    camera.position.set(c.x - 0.9 * r, c.y - 0.6 * r, c.z + 0.8 * r);  // behind and above, as the camera sees it
    controls.update();
  }
  const grid = new THREE.GridHelper(20, 20, 0x445566, 0x2a3038);
  grid.rotation.x = Math.PI / 2;  // GridHelper lies in x-z; the world's floor is x-y
  scene.add(grid);
  scene.add(new THREE.AxesHelper(0.5));

  let pointScale = 1;
  function resize() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    // A square of edge e metres at depth d covers e * pointScale / d pixels.
    pointScale = h / (2 * Math.tan(camera.fov * Math.PI / 360));
  }
  window.addEventListener('resize', resize);
  resize();

  // --- the map: one instanced cube per occupied cell, coloured by height -------------------
  // Each instance is vec4(centre, edge); cells are found by their four float32 words, and a
  // removed cell's slot takes the last instance, so the buffer stays dense.
  const map = { count: 0, capacity: 0, data: null, attr: null, index: new Map(), zMin: 0, zMax: 2.5 };
  const cellGeometry = new THREE.InstancedBufferGeometry();
  const box = new THREE.BoxBufferGeometry(1, 1, 1);
  cellGeometry.index = box.index;
  cellGeometry.setAttribute('position', box.getAttribute('position'));
  cellGeometry.setAttribute('normal', box.getAttribute('normal'));
  const cellMaterial = new THREE.ShaderMaterial({
    uniforms: { zMin: { value: 0 }, zMax: { value: 2.5 } },
    vertexShader: `
      attribute vec4 cell;
      uniform float zMin, zMax;
      varying vec3 vColor;
      vec3 ramp(float t) {  // blue (low) - cyan - green - yellow - red (high)
        return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
      }
      void main() {
        vec3 p = cell.xyz + position * cell.w;
        float t = clamp((cell.z - zMin) / max(zMax - zMin, 1e-3), 0.0, 1.0);
        float shade = 0.55 + 0.45 * abs(dot(normal, normalize(vec3(0.3, 0.5, 0.8))));
        vColor = ramp(t) * shade;
        gl_Position = projectionMatrix * modelViewMatrix * vec4(p, 1.0);
      }`,
    fragmentShader: `
      varying vec3 vColor;
      void main() { gl_FragColor = vec4(vColor, 1.0); }`,
  });
  const cellMesh = new THREE.Mesh(cellGeometry, cellMaterial);
  cellMesh.frustumCulled = false;  // the instances are far from the unit box's bounds
  scene.add(cellMesh);
  // Above kCubesUpTo cells the map is drawn as squares facing the camera, one vertex a cell
  // instead of a cube's 24: software GL (a browser without a GPU) then still draws 100,000
  // cells at an interactive rate (station/README.md, figures).
  const kCubesUpTo = 2000;
  const pointGeometry = new THREE.BufferGeometry();
  const pointMaterial = new THREE.ShaderMaterial({
    uniforms: { zMin: cellMaterial.uniforms.zMin, zMax: cellMaterial.uniforms.zMax, scale: { value: 1 } },
    vertexShader: `
      attribute vec4 cell;
      uniform float zMin, zMax, scale;
      varying vec3 vColor;
      vec3 ramp(float t) {
        return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), 0.0, 1.0);
      }
      void main() {
        vec4 mv = modelViewMatrix * vec4(cell.xyz, 1.0);
        vColor = ramp(clamp((cell.z - zMin) / max(zMax - zMin, 1e-3), 0.0, 1.0));
        gl_PointSize = max(1.0, scale * cell.w / -mv.z);
        gl_Position = projectionMatrix * mv;
      }`,
    fragmentShader: `
      varying vec3 vColor;
      void main() { gl_FragColor = vec4(vColor, 1.0); }`,
  });
  const cellPoints = new THREE.Points(pointGeometry, pointMaterial);
  cellPoints.frustumCulled = false;
  scene.add(cellPoints);

  function reserve(n) {
    if (n <= map.capacity) return;
    let cap = Math.max(1024, map.capacity);
    while (cap < n) cap *= 2;
    const data = new Float32Array(cap * 4);
    if (map.data) data.set(map.data.subarray(0, map.count * 4));
    map.data = data;
    map.capacity = cap;
    map.attr = new THREE.InstancedBufferAttribute(data, 4);
    map.attr.setUsage(THREE.DynamicDrawUsage);
    cellGeometry.setAttribute('cell', map.attr);
    map.pointAttr = new THREE.BufferAttribute(data, 4);
    map.pointAttr.setUsage(THREE.DynamicDrawUsage);
    pointGeometry.setAttribute('cell', map.pointAttr);
    pointGeometry.setAttribute('position', map.pointAttr);  // sets the draw count; the shader reads `cell`
  }
  // Above kPointBudget cells, each square stands for a block of 2^L x 2^L x 2^L cells, the
  // smallest L that keeps the squares within the budget (OctoMap's levels up, as octovis draws
  // a map at a chosen depth): software GL's cost is per primitive, and a map's surfaces have
  // about 4^L times fewer blocks than cells. The page still holds every cell (cellCount); only
  // the drawing is coarser.
  const kPointBudget = 25000;
  const coarse = { geometry: new THREE.BufferGeometry(), data: null, pending: false, blocks: 0, level: 0 };
  const coarsePoints = new THREE.Points(coarse.geometry, pointMaterial);
  coarsePoints.frustumCulled = false;
  coarsePoints.visible = false;
  scene.add(coarsePoints);
  function blocksAt(level) {
    const seen = new Set();
    const out = [];
    const e = map.data[3] * (1 << level);
    for (let i = 0; i < map.count; ++i) {
      const ix = Math.floor(map.data[4 * i] / e), iy = Math.floor(map.data[4 * i + 1] / e), iz = Math.floor(map.data[4 * i + 2] / e);
      const key = (ix + 32768) + 65536 * ((iy + 32768) + 65536 * (iz + 512));
      if (seen.has(key)) continue;
      seen.add(key);
      out.push((ix + 0.5) * e, (iy + 0.5) * e, (iz + 0.5) * e, e);
    }
    return out;
  }
  function buildCoarse() {
    coarse.pending = false;
    let level = 1, out = blocksAt(level);
    while (out.length / 4 > kPointBudget && level < 4) out = blocksAt(++level);
    coarse.data = new Float32Array(out);
    coarse.geometry.setAttribute('cell', new THREE.BufferAttribute(coarse.data, 4));
    coarse.geometry.setAttribute('position', coarse.geometry.getAttribute('cell'));
    coarse.blocks = out.length / 4;
    coarse.level = level;
  }
  // Cubes, squares or blocks, whichever suits the count; only what is drawn is uploaded.
  function showCells() {
    const cubes = map.count <= kCubesUpTo, blocks = map.count > kPointBudget;
    cellMesh.visible = cubes;
    cellPoints.visible = !cubes && !blocks;
    coarsePoints.visible = blocks;
    cellGeometry.maxInstancedCount = cubes ? map.count : 0;
    pointGeometry.setDrawRange(0, cubes || blocks ? 0 : map.count);
    if (cubes) map.attr.needsUpdate = true;
    else if (!blocks) map.pointAttr.needsUpdate = true;
    else if (!coarse.pending) {  // at most one rebuild a half second, off the socket's handler
      coarse.pending = true;
      setTimeout(buildCoarse, coarse.data ? 500 : 0);
    }
  }
  reserve(1024);
  function cellKey(w, i) { return w[i] + ',' + w[i + 1] + ',' + w[i + 2] + ',' + w[i + 3]; }

  // Applies one map message (wire.h); returns false for a malformed one.
  function applyMap(buffer) {
    const dv = new DataView(buffer);
    if (buffer.byteLength < 16) return false;
    const reset = (dv.getUint8(1) & 1) !== 0;
    const added = dv.getUint32(4, true), removed = dv.getUint32(8, true), after = dv.getUint32(12, true);
    if (buffer.byteLength !== 16 + 16 * (added + removed)) return false;
    const f = new Float32Array(buffer, 16, 4 * (added + removed));
    const words = new Uint32Array(buffer, 16, 4 * (added + removed));
    if (reset) { map.count = 0; map.index.clear(); }
    for (let k = 0; k < removed; ++k) {
      const i = 4 * (added + k);
      const key = cellKey(words, i);
      const slot = map.index.get(key);
      if (slot === undefined) continue;
      const last = map.count - 1;
      if (slot !== last) {
        map.data.copyWithin(slot * 4, last * 4, last * 4 + 4);
        const lw = new Uint32Array(map.data.buffer, last * 16, 4);
        map.index.set(cellKey(lw, 0), slot);
      }
      map.index.delete(key);
      map.count = last;
    }
    reserve(map.count + added);
    for (let k = 0; k < added; ++k) {
      const i = 4 * k;
      const key = cellKey(words, i);
      if (map.index.has(key)) continue;
      map.data.set(f.subarray(i, i + 4), map.count * 4);
      map.index.set(key, map.count);
      map.count += 1;
    }
    showCells();
    if (map.count !== after) console.warn('map: ' + map.count + ' cells, the station says ' + after);
    return true;
  }

  // --- the vehicle, its covariance, the paths, the graph, the plan -------------------------
  const vehicle = new THREE.Group();
  const body = new THREE.Mesh(new THREE.BoxBufferGeometry(0.3, 0.3, 0.06), new THREE.MeshBasicMaterial({ color: 0xffffff }));
  const nose = new THREE.Mesh(new THREE.ConeBufferGeometry(0.05, 0.2, 12), new THREE.MeshBasicMaterial({ color: 0xff3030 }));
  nose.rotation.z = -Math.PI / 2;  // the cone points along +x: the body's forward
  nose.position.x = 0.22;
  vehicle.add(body, nose);
  vehicle.visible = false;
  scene.add(vehicle);
  const ellipsoid = new THREE.Mesh(new THREE.SphereBufferGeometry(1, 16, 12),
    new THREE.MeshBasicMaterial({ color: 0x40c0ff, wireframe: true, transparent: true, opacity: 0.6 }));
  ellipsoid.visible = false;
  scene.add(ellipsoid);

  function makeLine(color) {
    const line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color }));
    line.frustumCulled = false;
    scene.add(line);
    return line;
  }
  function setLine(line, points) {
    const a = new Float32Array(points.length * 3);
    points.forEach((p, i) => a.set([p[0], p[1], p[2]], 3 * i));
    line.geometry.setAttribute('position', new THREE.BufferAttribute(a, 3));
    line.geometry.setDrawRange(0, points.length);
  }
  const path = makeLine(0x40c0ff), truthPath = makeLine(0x50e050), planLine = makeLine(0xff9020);
  const truthMarker = new THREE.Mesh(new THREE.SphereBufferGeometry(0.06, 10, 8), new THREE.MeshBasicMaterial({ color: 0x50e050 }));
  truthMarker.visible = false;
  scene.add(truthMarker);
  const keyframes = new THREE.Points(new THREE.BufferGeometry(), new THREE.PointsMaterial({ color: 0xffff80, size: 5, sizeAttenuation: false }));
  keyframes.frustumCulled = false;
  scene.add(keyframes);
  function makeSegments(color) {
    const s = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color }));
    s.frustumCulled = false;
    scene.add(s);
    return s;
  }
  const odometryEdges = makeSegments(0x707060), loopEdges = makeSegments(0xff40ff);
  function setSegments(seg, points, pairs) {
    const a = new Float32Array(pairs.length * 6);
    pairs.forEach(([i, j], k) => a.set([...points[i], ...points[j]], 6 * k));
    seg.geometry.setAttribute('position', new THREE.BufferAttribute(a, 3));
  }
  const planDiscs = new THREE.Group();
  scene.add(planDiscs);
  const discGeometry = new THREE.RingBufferGeometry(0.97, 1.0, 32);
  const discMaterial = new THREE.MeshBasicMaterial({ color: 0xff9020, side: THREE.DoubleSide, transparent: true, opacity: 0.7 });

  // --- the panel -------------------------------------------------------------------------
  const $ = (id) => document.getElementById(id);
  const fmt = (v, n = 2) => Number(v).toFixed(n);
  const state = { vehicle: null, health: [], notice: null, notices: 0, frames: 0, plan: null, mapInfo: null, playback: null };
  let seeking = false;  // the seek bar is being dragged: the replay's position does not move it

  function onJson(u) {
    switch (u.kind) {
      case 'state': {
        state.vehicle = u;
        vehicle.visible = true;
        vehicle.position.set(u.p[0], u.p[1], u.p[2]);
        vehicle.quaternion.set(u.q[1], u.q[2], u.q[3], u.q[0]);
        if (u.cov) {
          ellipsoid.visible = true;
          ellipsoid.position.copy(vehicle.position);
          ellipsoid.quaternion.set(u.cov.q[1], u.cov.q[2], u.cov.q[3], u.cov.q[0]);
          // 1 sigma, never thinner than 5 mm so that it stays visible.
          ellipsoid.scale.set(...u.cov.radii.map((r) => Math.max(r, 0.005)));
        } else {
          ellipsoid.visible = false;
        }
        $('vehicle').textContent = `vehicle: (${fmt(u.p[0])}, ${fmt(u.p[1])}, ${fmt(u.p[2])}) yaw ${fmt(u.yaw)}` +
          (u.cov ? `, 1σ ${u.cov.radii.map((r) => fmt(100 * r, 1)).join('/')} cm` : '') + ` (t ${fmt(u.utime / 1e6, 1)} s)`;
        break;
      }
      case 'path': setLine(path, u.points); break;
      case 'truth_path': setLine(truthPath, u.points); break;
      case 'truth_pose':
        truthMarker.visible = true;
        truthMarker.position.set(u.p[0], u.p[1], u.p[2]);
        break;
      case 'graph': {
        const g = new THREE.BufferGeometry();
        g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(u.keyframes.flat()), 3));
        keyframes.geometry = g;
        setSegments(odometryEdges, u.keyframes, u.odometry);
        setSegments(loopEdges, u.keyframes, u.loops);
        break;
      }
      case 'plan': {
        state.plan = u;
        setLine(planLine, u.waypoints);
        while (planDiscs.children.length) planDiscs.remove(planDiscs.children[0]);
        // The belief model's 1-sigma horizontal ellipse at each waypoint when PLAN_COVARIANCE
        // came with the plan, else a disc of the RMS sigma its trace gives.
        u.waypoints.forEach((w, i) => {
          const e = u.ellipses ? u.ellipses[i] : [u.sigma[i], u.sigma[i], 0];
          if (!(e[0] > 0)) return;
          const d = new THREE.Mesh(discGeometry, discMaterial);
          d.position.set(w[0], w[1], w[2]);
          d.scale.set(e[0], Math.max(e[1], 1e-3), 1);
          d.rotation.z = e[2];
          planDiscs.add(d);
        });
        $('planinfo').textContent = u.request_id < 0 ? 'plan: none' :
          `plan ${u.request_id}: ${u.status_name}, ${u.waypoints.length} waypoints, ${fmt(u.length)} m` +
          (u.message ? ` (${u.message})` : '');
        break;
      }
      case 'map_info':
        state.mapInfo = u;
        if (u.bounds) {
          cellMaterial.uniforms.zMin.value = u.bounds[2];
          cellMaterial.uniforms.zMax.value = u.bounds[5];
          if (!userMoved) frameBounds(u.bounds);
        }
        $('mapinfo').textContent = `map: revision ${u.revision}, ${u.cells} occupied cells at ${fmt(100 * u.resolution, 0)} cm`;
        break;
      case 'health': {
        state.health = u.processes;
        const rows = u.processes.map((p) => {
          const cls = p.state_name === 'RUNNING' ? 'ok' : (p.state_name === 'DEGRADED' || p.state_name === 'STARTING') ? 'warn' : 'bad';
          return `<tr><td>${esc(p.name)}</td><td class="${cls}">${p.state_name}</td><td>${p.in}</td><td>${p.out}</td>` +
            `<td>${p.rejected}</td><td>${fmt(p.age_s, 1)} s</td><td>${esc(p.message)}</td></tr>`;
        });
        $('health').tBodies[0].innerHTML = rows.join('');
        break;
      }
      case 'rates':
        $('rates').tBodies[0].innerHTML = u.channels.map((c) =>
          `<tr><td>${esc(c.channel)}</td><td>${fmt(c.hz, 1)}</td><td>${fmt(c.bytes_per_s / 1000, 1)}</td></tr>`).join('');
        break;
      case 'playback': {
        // A controlled replay (`kestrel replay LOG --control`): its transport bar.
        state.playback = u;
        $('playback').hidden = false;
        $('playpause').textContent = u.at_end ? 'replay' : u.paused ? 'play' : 'pause';
        $('seek').max = u.length;
        if (!seeking) $('seek').value = u.t;
        $('ptime').textContent = `${fmt(u.t, 1)} / ${fmt(u.length, 1)} s`;
        $('ptime').title = u.log;
        const speed = [...$('pspeed').options].find((o) => parseFloat(o.value) === u.speed);
        if (speed) $('pspeed').value = speed.value;
        break;
      }
      case 'notice':
        state.notice = u;
        state.notices += 1;
        $('notice').textContent = u.text;
        $('notice').className = u.ok ? 'ok' : 'bad';
        break;
      default: break;
    }
  }
  function esc(s) { return String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c])); }

  const imageUrls = {};
  function showImage(id, bytes, format) {
    const url = URL.createObjectURL(new Blob([bytes], { type: format === 1 ? 'image/png' : 'image/jpeg' }));
    if (imageUrls[id]) URL.revokeObjectURL(imageUrls[id]);
    imageUrls[id] = url;
    $(id).src = url;
  }
  function onBinary(buffer) {
    const kind = new DataView(buffer).getUint8(0);
    if (kind === 1) { applyMap(buffer); return; }
    if ((kind === 2 || kind === 3) && buffer.byteLength >= 8) {
      const dv = new DataView(buffer);
      const n = dv.getUint32(4, true);
      if (8 + n !== buffer.byteLength) return;
      showImage(kind === 2 ? 'colour' : 'depth', new Uint8Array(buffer, 8, n), dv.getUint8(1));
    }
  }

  // --- the socket ------------------------------------------------------------------------
  let socket = null;
  const received = { total: 0 };
  function connect() {
    const url = `ws://${location.host}/ws` + (token ? `?token=${encodeURIComponent(token)}` : '');
    socket = new WebSocket(url);
    socket.binaryType = 'arraybuffer';
    socket.onopen = () => { $('link').textContent = 'live'; $('link').className = 'ok'; };
    socket.onclose = () => {
      $('link').textContent = 'disconnected'; $('link').className = 'bad';
      setTimeout(connect, 1000);
    };
    socket.onmessage = (e) => {
      // Payload bytes received, per kind: the socket's traffic figure (station/README.md).
      const n = typeof e.data === 'string' ? e.data.length : e.data.byteLength;
      const kind = typeof e.data === 'string' ? 'json' : (['', 'map', 'colour', 'depth'][new DataView(e.data).getUint8(0)] || 'other');
      received[kind] = (received[kind] || 0) + n;
      received.total += n;
      if (typeof e.data === 'string') {
        try { onJson(JSON.parse(e.data)); } catch (err) { console.warn('bad update', err); }
      } else {
        onBinary(e.data);
      }
    };
  }
  connect();
  function send(cmd) {
    if (token) cmd.token = token;
    if (!socket || socket.readyState !== WebSocket.OPEN) {
      onJson({ kind: 'notice', ok: false, text: 'not connected: nothing sent' });
      return false;
    }
    socket.send(JSON.stringify(cmd));
    return true;
  }
  function numberIn(id) { return parseFloat($(id).value); }
  function sendGoal() {
    const g = [numberIn('gx'), numberIn('gy'), numberIn('gz'), numberIn('gyaw')];
    if (!g.every(Number.isFinite)) { onJson({ kind: 'notice', ok: false, text: 'goal: x y z yaw must be numbers' }); return; }
    send({ cmd: 'goal', goal: g });
  }
  $('goal').addEventListener('submit', (e) => { e.preventDefault(); sendGoal(); });
  $('hold').addEventListener('click', () => send({ cmd: 'hold' }));
  $('playpause').addEventListener('click', () => {
    const p = state.playback;
    if (!p) return;
    if (p.at_end) { send({ cmd: 'seek', t: 0 }); send({ cmd: 'play' }); return; }
    send({ cmd: p.paused ? 'play' : 'pause' });
  });
  $('seek').addEventListener('input', () => { seeking = true; });
  // A drag that ends where it began fires no change: the bar follows the replay again anyway.
  $('seek').addEventListener('pointerup', () => { seeking = false; });
  $('seek').addEventListener('blur', () => { seeking = false; });
  $('seek').addEventListener('change', () => { seeking = false; send({ cmd: 'seek', t: parseFloat($('seek').value) }); });
  $('pspeed').addEventListener('change', () => send({ cmd: 'speed', speed: parseFloat($('pspeed').value) }));

  // A click (not a drag) on the map: the point under it at height z becomes the goal.
  const raycaster = new THREE.Raycaster();
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
    const p = clientToWorld(e.clientX, e.clientY, numberIn('gz'));
    if (!p) return;
    $('gx').value = fmt(p.x, 3);
    $('gy').value = fmt(p.y, 3);
    sendGoal();
  });
  function clientToWorld(cx, cy, z) {
    if (!Number.isFinite(z)) return null;
    const r = renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((cx - r.left) / r.width) * 2 - 1, -((cy - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(ndc, camera);
    const hit = new THREE.Vector3();
    return raycaster.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), -z), hit) ? hit : null;
  }
  function worldToClient(x, y, z) {
    const v = new THREE.Vector3(x, y, z).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height };
  }

  function frame() {
    controls.update();
    pointMaterial.uniforms.scale.value = pointScale;
    renderer.render(scene, camera);
    state.frames += 1;
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);

  // What tests and measurements read (test/station/browser/check.js).
  window.station = {
    cellCount: () => map.count,
    drawn: () => (coarsePoints.visible ? { blocks: coarse.blocks, level: coarse.level } : null),
    received: () => Object.assign({}, received),
    vehiclePosition: () => (vehicle.visible ? [vehicle.position.x, vehicle.position.y, vehicle.position.z] : null),
    healthNames: () => state.health.map((p) => p.name),
    lastNotice: () => state.notice,
    notices: () => state.notices,
    frames: () => state.frames,
    mapInfo: () => state.mapInfo,
    plan: () => state.plan,
    playback: () => state.playback,
    worldToClient,
    // Frames the map's message path (applyMap) exactly as the socket does; for measurements.
    applyMapMessage: (buffer) => applyMap(buffer),
    // Renders a frame and reads it back at once (the drawing buffer is not kept between
    // frames, which software GL would pay for on every frame): how much of the canvas is not
    // the background, and how many colours it holds.
    canvasStats: () => {
      renderer.render(scene, camera);
      const gl = renderer.getContext();
      const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
      const d = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, d);
      const bg = [d[0], d[1], d[2]];
      let other = 0;
      const colours = new Set();
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) other += 1;
        if (colours.size < 5000) colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
      }
      return { width: w, height: h, non_background: other / (w * h), colours: colours.size };
    },
    lookAt: (x, y, z, fromX, fromY, fromZ) => {
      userMoved = true;
      controls.target.set(x, y, z); camera.position.set(fromX, fromY, fromZ); controls.update();
    },
  };
})();
