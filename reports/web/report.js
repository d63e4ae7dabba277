// report.html's interactive parts (reports/web_page.cpp writes the page): Chart.js plots with
// hover, series toggles and box zoom; per scene, the models' deformed walls in 3D drawn by one
// three.js renderer for the whole page, their data decoded when the scene scrolls into view.
(function () {
  'use strict';
  const report = (window.vvReport = {charts: [], views: [], interactiveMs: null});

  // Viridis (van der Walt & Smith 2015), 11 stops: perceptually uniform, readable in grey.
  const VIRIDIS = [[68, 1, 84], [72, 35, 116], [64, 67, 135], [52, 94, 141], [41, 120, 142],
    [32, 144, 140], [34, 167, 132], [68, 190, 112], [121, 209, 81], [189, 222, 38], [253, 231, 37]];
  function viridis(t) {
    const s = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
    const i = Math.min(VIRIDIS.length - 2, Math.floor(s));
    const f = s - i;
    return [0, 1, 2].map((k) => (VIRIDIS[i][k] + (VIRIDIS[i + 1][k] - VIRIDIS[i][k]) * f) / 255);
  }

  function decode(text, Type) {
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }
  report.decode = decode;

  function fmt(v) {
    if (v === null || v === undefined) return '–';
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e4) ? v.toExponential(2) : String(+v.toPrecision(3));
  }

  function whenVisible(el, init) {
    const io = new IntersectionObserver((entries) => {
      if (entries.some((e) => e.isIntersecting)) {
        io.disconnect();
        init();
      }
    }, {rootMargin: '300px'});
    io.observe(el);
  }

  // ---------------------------------------------------------------------------------- plots --
  function makeChart(box, plot, index) {
    if (box.vvChart) return;
    box.vvChart = true;
    const canvas = box.querySelector('canvas');
    const datasets = plot.series.map((s) => {
      const data = [];
      s.x.forEach((x, i) => {
        const y = s.y[i];
        if (x === null || y === null || (plot.x.log && x <= 0) || (plot.y.log && y <= 0)) return;
        data.push({x: x, y: y, label: s.labels[i] || '', view: s.views[i] || ''});
      });
      const colour = s.colour || '#555555';
      return {label: s.label, data: data, borderColor: colour, backgroundColor: colour,
        pointStyle: s.marker || 'circle', showLine: s.lines, borderDash: s.dashed ? [6, 4] : [],
        borderWidth: s.emphasis ? 3 : 1.6, pointRadius: s.markers ? (s.emphasis ? 4 : 4) : 0,
        pointHoverRadius: s.markers ? 7 : 4, pointHitRadius: 6, fill: false};
    });
    const axis = (a) => ({type: a.log ? 'logarithmic' : 'linear',
      title: {display: true, text: a.label},
      ticks: {callback: (v) => fmt(v), maxTicksLimit: 9}});
    const chart = new Chart(canvas, {
      type: 'scatter',
      data: {datasets: datasets},
      options: {
        animation: false, responsive: true, maintainAspectRatio: false,
        scales: {x: axis(plot.x), y: axis(plot.y)},
        plugins: {
          title: {display: true, text: plot.title},
          legend: {position: 'bottom', labels: {usePointStyle: true, boxHeight: 7}},
          tooltip: {callbacks: {label: (ctx) => ctx.dataset.label + ': ' +
            (ctx.raw.label ? ctx.raw.label + '; ' : '') + 'x = ' + fmt(ctx.raw.x) +
            ', y = ' + fmt(ctx.raw.y)}}},
        onClick: (event, elements) => {
          if (!elements.length) return;
          const p = chart.data.datasets[elements[0].datasetIndex].data[elements[0].index];
          if (p.view) showInView(p.view);
        }}});
    addBoxZoom(box, chart);
    const reset = box.parentElement.querySelector('.vv-reset');
    if (reset) reset.addEventListener('click', () => resetZoom(chart));
    report.charts.push({index: index, title: plot.title, chart: chart});
  }

  function resetZoom(chart) {
    for (const k of ['x', 'y']) {
      delete chart.options.scales[k].min;
      delete chart.options.scales[k].max;
    }
    chart.update('none');
  }

  // Box zoom: drag across the plot area; the reset button restores the full range.
  function addBoxZoom(box, chart) {
    let start = null;
    const rect = document.createElement('div');
    rect.className = 'vv-zoombox';
    rect.style.display = 'none';
    box.appendChild(rect);
    const at = (e) => {
      const r = chart.canvas.getBoundingClientRect();
      return {x: e.clientX - r.left, y: e.clientY - r.top};
    };
    chart.canvas.addEventListener('mousedown', (e) => { start = at(e); });
    chart.canvas.addEventListener('mousemove', (e) => {
      if (!start) return;
      const p = at(e);
      Object.assign(rect.style, {display: 'block', left: Math.min(p.x, start.x) + 'px',
        top: Math.min(p.y, start.y) + 'px', width: Math.abs(p.x - start.x) + 'px',
        height: Math.abs(p.y - start.y) + 'px'});
    });
    window.addEventListener('mouseup', (e) => {
      if (!start) return;
      const p = at(e);
      rect.style.display = 'none';
      if (Math.abs(p.x - start.x) > 6 && Math.abs(p.y - start.y) > 6) {
        const sx = chart.scales.x, sy = chart.scales.y;
        chart.options.scales.x.min = sx.getValueForPixel(Math.min(p.x, start.x));
        chart.options.scales.x.max = sx.getValueForPixel(Math.max(p.x, start.x));
        chart.options.scales.y.min = sy.getValueForPixel(Math.max(p.y, start.y));
        chart.options.scales.y.max = sy.getValueForPixel(Math.min(p.y, start.y));
        chart.update('none');
      }
      start = null;
    });
  }

  // ---------------------------------------------------------------------------- 3D views --
  let renderer = null;
  let frameRequested = false;
  const tip = document.createElement('div');
  tip.className = 'vv-tip';

  function requestRender() {
    if (frameRequested || !renderer) return;
    frameRequested = true;
    requestAnimationFrame(() => { frameRequested = false; renderAll(); });
  }
  report.requestRender = requestRender;
  report.renderNow = () => renderAll();

  function ensureRenderer() {
    if (renderer) return;
    const canvas = document.createElement('canvas');
    canvas.id = 'vv-gl';
    document.body.appendChild(canvas);
    document.body.appendChild(tip);
    renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true, alpha: true,
      preserveDrawingBuffer: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    const resize = () => { renderer.setSize(window.innerWidth, window.innerHeight, false);
      requestRender(); };
    report.gl = renderer.getContext();
    resize();
    window.addEventListener('resize', resize);
    window.addEventListener('scroll', requestRender, {passive: true});
  }

  function renderAll() {
    const height = window.innerHeight;
    renderer.setScissorTest(false);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.setScissorTest(true);
    for (const view of report.views) {
      placeCamera(view);
      // The camera is in no scene, so render() would not update its world matrix in time for
      // the first pane drawn.
      view.camera.updateMatrixWorld();
      for (const pane of view.panes) {
        pane.light.position.copy(view.camera.localToWorld(new THREE.Vector3(0, 1, 0)));
        pane.light.target.position.copy(view.centre);
        const r = pane.el.getBoundingClientRect();
        if (r.bottom < 0 || r.top > height || r.width <= 2) continue;
        const w = r.width - 2, h = r.height - 2;  // inside the border
        renderer.setViewport(r.left + 1, height - r.bottom + 1, w, h);
        renderer.setScissor(r.left + 1, height - r.bottom + 1, w, h);
        renderer.setClearColor(0xf6f6f6, 1);
        renderer.clear();
        view.camera.aspect = w / h;
        view.camera.updateProjectionMatrix();
        renderer.render(pane.scene, view.camera);
      }
    }
  }

  // What the colours show and in what unit (|error| in mm unless the view says otherwise), and a
  // wall's name with its mesh level when it has one.
  function colourName(view) { return view.data.colour ? view.data.colour.name : '|error|'; }
  function colourUnit(view) { return view.data.colour ? view.data.colour.unit : 'mm'; }
  function modelName(m) { return m.level === null ? m.model : m.model + ' (L' + m.level + ')'; }

  /// A model's decoded arrays (decoded once, when first shown).
  function modelData(view, i) {
    const m = view.data.views[i];
    if (!m.decoded) {
      m.decoded = {rest: decode(m.rest, Float32Array), um: decode(m.um, Float32Array),
        ur: decode(m.ur, Float32Array),
        idx: decode(m.idx, m.idx_bytes === 2 ? Uint16Array : Uint32Array),
        err: decode(m.err, Uint16Array)};
    }
    return m;
  }

  function springEdges(idx) {
    const seen = new Set();
    const out = [];
    for (let t = 0; t < idx.length; t += 3) {
      for (let k = 0; k < 3; ++k) {
        const a = idx[t + k], b = idx[t + (k + 1) % 3];
        const key = a < b ? a * 4294967296 + b : b * 4294967296 + a;
        if (!seen.has(key)) { seen.add(key); out.push(a, b); }
      }
    }
    return idx instanceof Uint16Array ? new Uint16Array(out) : new Uint32Array(out);
  }

  function deformed(m, u, factor) {
    const d = m.decoded, out = new Float32Array(d.rest.length);
    for (let i = 0; i < out.length; ++i) out[i] = d.rest[i] + factor * d[u][i];
    return out;
  }

  function buildPane(view, pane) {
    const scene = new THREE.Scene();
    scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    // A headlight per pane, placed at the shared camera before each frame (renderAll): the
    // camera cannot be a child of both panes' scenes, three.js keeps an object in one parent.
    pane.light = new THREE.DirectionalLight(0xffffff, 0.6);
    scene.add(pane.light, pane.light.target);
    pane.scene = scene;
    if (view.ghost >= 0) {
      const g = modelData(view, view.ghost);
      const geom = new THREE.BufferGeometry();
      geom.setAttribute('position', new THREE.BufferAttribute(deformed(g, 'ur', view.factor), 3));
      geom.setIndex(new THREE.BufferAttribute(g.decoded.idx, 1));
      const ghost = g.lines ? new THREE.LineSegments(geom, new THREE.LineBasicMaterial(
        {color: 0x888888, transparent: true, opacity: 0.25}))
        : new THREE.Mesh(geom, new THREE.MeshBasicMaterial({color: 0x777777, transparent: true,
          opacity: 0.13, depthWrite: false, side: THREE.DoubleSide}));
      ghost.renderOrder = 2;
      pane.ghost = ghost;
      scene.add(ghost);
    }
    // The QoI point and the contact patch at rest, drawn over the wall (they sit on the
    // inner wall, which the wall itself hides).
    if (view.data.qoi_mm) {
      // Small enough inside the patch for its rim to show around it.
      const r = view.data.patch ? 0.25 * view.data.patch.radius_mm : view.radius * 0.035;
      const s = new THREE.Mesh(new THREE.SphereBufferGeometry(r, 16, 12),
        new THREE.MeshBasicMaterial({color: 0xdd0000, depthTest: false}));
      s.position.set(view.data.qoi_mm[0], view.data.qoi_mm[1], view.data.qoi_mm[2]);
      s.renderOrder = 3;
      scene.add(s);
    }
    if (view.data.patch) patchMarks(view.data.patch).forEach((m) => scene.add(m));
    if (view.data.wire) showWire(view, pane);
    const label = document.createElement('div');
    label.className = 'vv-pane-label';
    pane.el.appendChild(label);
    pane.label = label;
  }

  // The contact patch: a translucent disc of its radius about its centre in the wall's tangent
  // plane (normal to the patch's outward normal), and its rim.
  function patchMarks(patch) {
    const n = new THREE.Vector3().fromArray(patch.normal).normalize();
    const e1 = new THREE.Vector3(1, 0, 0);
    if (Math.abs(n.x) > 0.9) e1.set(0, 1, 0);
    e1.sub(n.clone().multiplyScalar(e1.dot(n))).normalize();
    const e2 = n.clone().cross(e1);
    const points = [];
    for (let k = 0; k < 64; ++k) {
      const a = 2 * Math.PI * k / 64, r = patch.radius_mm;
      points.push(new THREE.Vector3().fromArray(patch.point_mm)
        .addScaledVector(e1, r * Math.cos(a)).addScaledVector(e2, r * Math.sin(a)));
    }
    const ring = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(points),
      new THREE.LineBasicMaterial({color: 0xdd0000, depthTest: false}));
    const fan = new THREE.BufferGeometry().setFromPoints(
      [new THREE.Vector3().fromArray(patch.point_mm)].concat(points, [points[0]]));
    fan.setIndex(points.map((p, k) => [0, k + 1, k + 2]).flat());  // r111: returns nothing
    const disc = new THREE.Mesh(fan, new THREE.MeshBasicMaterial({color: 0xdd0000,
      transparent: true, opacity: 0.3, depthTest: false, side: THREE.DoubleSide}));
    ring.renderOrder = 3;
    disc.renderOrder = 3;
    return [disc, ring];
  }

  // The guidewire's centreline at the deformation scale: the rigid wire, or with compliant
  // coupling the rigid wire plus `factor` times the reference-coupled wire's give from it (so it
  // stays on the wall drawn at the same scale).
  function wirePoints(wire, factor, coupled) {
    return wire.rigid_mm.map((p, k) => {
      const v = new THREE.Vector3().fromArray(p);
      if (coupled) v.addScaledVector(new THREE.Vector3().fromArray(wire.coupled_mm[k]).sub(v), factor);
      return v;
    });
  }

  // The wire as an orange tube drawn through the wall (no depth test: the wall does not hide it);
  // with compliant coupling a dark line adds the wire against the rigid lumen.
  function showWire(view, pane) {
    const wire = view.data.wire;
    for (const key of ['wire', 'rigidWire']) {
      if (pane[key]) { pane.scene.remove(pane[key]); pane[key].geometry.dispose(); pane[key] = null; }
    }
    const coupled = !!wire.coupled_mm && wire.coupled_mm.length === wire.rigid_mm.length;
    const curve = new THREE.CatmullRomCurve3(wirePoints(wire, view.factor, coupled));
    const radius = Math.max(wire.radius_mm, 0.004 * view.radius);
    // At true scale the wire sits where it is, so the wall may hide it; half transparent, so the
    // contact under it shows. Magnified walls leave it behind: then it is drawn through them.
    const inPlace = !!view.data.true_scale;
    const tube = new THREE.Mesh(new THREE.TubeBufferGeometry(curve, 4 * wire.rigid_mm.length,
      radius, 10, false), new THREE.MeshLambertMaterial({color: 0xff8c00, depthTest: inPlace,
      depthWrite: false, transparent: true, opacity: inPlace ? 0.5 : 1}));
    tube.renderOrder = 5;
    pane.wire = tube;
    pane.scene.add(tube);
    if (coupled) {
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(
        wirePoints(wire, 0, false)), new THREE.LineBasicMaterial({color: 0x222222,
        depthTest: false, transparent: true}));
      line.renderOrder = 6;
      pane.rigidWire = line;
      pane.scene.add(line);
    }
    const shown = view.section.querySelector('.vv-wire');
    if (shown) { tube.visible = shown.checked; if (pane.rigidWire) pane.rigidWire.visible = shown.checked; }
  }

  /// The smallest sphere about the box centre of everything the view's panes draw (the models
  /// and the ghost as deformed now, the wire): the camera keeps it all in sight.
  function fitSphere(view) {
    const arrays = [];
    for (const pane of view.panes) {
      for (const o of [pane.mesh, pane.ghost, pane.wire, pane.rigidWire]) {
        if (o) arrays.push(o.geometry.getAttribute('position').array);
      }
    }
    const box = new THREE.Box3();
    arrays.forEach((a) => box.union(new THREE.Box3().setFromArray(a)));
    const centre = box.getCenter(new THREE.Vector3());
    let r2 = 0;
    for (const a of arrays) {
      for (let k = 0; k < a.length; k += 3) {
        const dx = a[k] - centre.x, dy = a[k + 1] - centre.y, dz = a[k + 2] - centre.z;
        r2 = Math.max(r2, dx * dx + dy * dy + dz * dz);
      }
    }
    view.fit = {centre: centre, radius: Math.max(Math.sqrt(r2), 1e-9 * view.radius)};
    view.centre = centre;
    requestRender();
  }

  /// The shared camera on its orbit about the fitted sphere, at the distance where the sphere
  /// fills the narrower of the panes' two fields of view (half-angle a: distance R / sin a), with
  /// a margin, times the reader's dolly.
  function placeCamera(view) {
    const c = view.camera, o = view.orbit, fit = view.fit;
    let aspect = Infinity;
    for (const pane of view.panes) {
      const r = pane.el.getBoundingClientRect();
      if (r.width > 2 && r.height > 2) aspect = Math.min(aspect, (r.width - 2) / (r.height - 2));
    }
    if (!isFinite(aspect)) aspect = 1.5;
    const half = Math.min(c.fov / 2, Math.atan(Math.tan(c.fov / 2 * Math.PI / 180) * aspect) *
      180 / Math.PI) * Math.PI / 180;
    const d = 1.1 * fit.radius / Math.sin(half) * o.zoom;
    c.position.set(fit.centre.x + d * Math.sin(o.phi) * Math.sin(o.theta),
      fit.centre.y + d * Math.cos(o.phi), fit.centre.z + d * Math.sin(o.phi) * Math.cos(o.theta));
    c.near = Math.max(d - 2 * fit.radius, d * 1e-3);
    c.far = d + 2 * fit.radius;
    c.lookAt(fit.centre);
  }

  function showModel(view, pane, i) {
    const m = modelData(view, i);
    if (pane.mesh) { pane.scene.remove(pane.mesh); pane.mesh.geometry.dispose(); }
    if (pane.springs) { pane.scene.remove(pane.springs); pane.springs.geometry.dispose(); }
    const d = m.decoded;
    const colours = new Float32Array(d.err.length * 3);
    for (let k = 0; k < d.err.length; ++k) {
      const c = viridis(scaleAt(view, d.err[k] * m.step));
      colours[3 * k] = c[0]; colours[3 * k + 1] = c[1]; colours[3 * k + 2] = c[2];
    }
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.BufferAttribute(deformed(m, 'um', view.factor), 3));
    geom.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    geom.setIndex(new THREE.BufferAttribute(d.idx, 1));
    if (m.lines) {
      pane.mesh = new THREE.LineSegments(geom, new THREE.LineBasicMaterial(
        {vertexColors: THREE.VertexColors}));
    } else {
      geom.computeVertexNormals();
      pane.mesh = new THREE.Mesh(geom, new THREE.MeshLambertMaterial(
        {vertexColors: THREE.VertexColors, side: THREE.DoubleSide}));
      if (m.springs) {
        const eg = new THREE.BufferGeometry();
        eg.setAttribute('position', geom.getAttribute('position'));
        eg.setIndex(new THREE.BufferAttribute(springEdges(d.idx), 1));
        pane.springs = new THREE.LineSegments(eg, new THREE.LineBasicMaterial(
          {color: 0x222222, transparent: true, opacity: 0.35}));
        pane.scene.add(pane.springs);
      }
    }
    pane.scene.add(pane.mesh);
    pane.model = i;
    pane.label.textContent = modelName(m) + ', max ' + colourName(view) + ' ' + fmt(m.max) + ' ' +
      colourUnit(view);
    fitSphere(view);
  }

  function setFactor(view, factor) {
    view.factor = factor;
    view.section.querySelector('.vv-scale-text').textContent = ' ' + fmt(factor);
    for (const pane of view.panes) {
      if (pane.ghost) {
        pane.ghost.geometry.setAttribute('position', new THREE.BufferAttribute(
          deformed(view.data.views[view.ghost], 'ur', factor), 3));
      }
      if (pane.model !== undefined) showModel(view, pane, pane.model);
      if (view.data.wire && view.data.wire.coupled_mm) showWire(view, pane);
    }
    fitSphere(view);
  }

  /// Where an error sits on the colour scale, 0 to 1: linear from 0 to the scene's largest error,
  /// or logarithmic over its three decades below it.
  function scaleAt(view, e) {
    if (!view.logScale) return e / view.scaleMax;
    const lo = view.scaleMax * 1e-3;
    return Math.log10(Math.max(e, lo) / lo) / 3;
  }

  function colourBar(view) {
    const bar = view.section.querySelector('.vv-colourbar');
    bar.textContent = '';
    const stops = VIRIDIS.map((c, i) => 'rgb(' + c.join(',') + ') ' + (100 * i / 10) + '%');
    bar.style.background = 'linear-gradient(to right,' + stops.join(',') + ')';
    const tick = (at, text, cls) => {
      const s = document.createElement('span');
      s.style.left = (100 * at) + '%';
      s.textContent = text;
      if (cls) s.className = cls;
      bar.appendChild(s);
    };
    const unit = ' ' + colourUnit(view);
    tick(0, view.logScale ? '≤ ' + fmt(view.scaleMax * 1e-3) + unit : '0' + unit);
    if (view.logScale) {
      tick(1 / 3, fmt(view.scaleMax * 1e-2) + unit);
      tick(2 / 3, fmt(view.scaleMax * 1e-1) + unit);
    }
    tick(1, fmt(view.scaleMax) + unit);
    const tol = view.data.tolerance_mm;
    if (tol === null || tol === undefined) return;  // a view without a tolerance (the insertion's)
    if (tol < view.scaleMax) {
      const line = document.createElement('div');
      line.className = 'vv-tol';
      line.style.left = (100 * scaleAt(view, tol)) + '%';
      bar.appendChild(line);
      tick(scaleAt(view, tol), 'tolerance ' + fmt(tol) + ' mm', 'vv-tol-label');
    } else {
      tick(1, 'tolerance ' + fmt(tol) + ' mm (all within)', 'vv-tol-label');
    }
  }

  // Orbit by dragging, dolly by the wheel: one camera for both panes.
  function addOrbit(view) {
    let drag = null;
    const place = () => requestRender();  // renderAll places the camera (placeCamera)
    for (const pane of view.panes) {
      pane.el.addEventListener('pointerdown', (e) => { drag = {x: e.clientX, y: e.clientY};
        pane.el.setPointerCapture(e.pointerId); });
      pane.el.addEventListener('pointerup', () => { drag = null; });
      pane.el.addEventListener('pointermove', (e) => {
        if (drag) {
          view.orbit.theta -= (e.clientX - drag.x) * 0.01;
          view.orbit.phi = Math.min(3.1, Math.max(0.05, view.orbit.phi - (e.clientY - drag.y) * 0.01));
          drag = {x: e.clientX, y: e.clientY};
          place();
        } else {
          hover(view, pane, e);
        }
      });
      pane.el.addEventListener('pointerleave', () => { tip.style.display = 'none'; });
      pane.el.addEventListener('wheel', (e) => {
        e.preventDefault();
        view.orbit.zoom *= Math.exp(e.deltaY * 0.001);
        place();
      }, {passive: false});
    }
    place();
  }

  const raycaster = new (window.THREE ? THREE.Raycaster : Object)();

  /// The node nearest to the pointer's hit on a pane's wall: its error and both displacements.
  function nodeAt(view, pane, clientX, clientY) {
    if (!pane.mesh) return null;
    const r = pane.el.getBoundingClientRect();
    const ndc = new THREE.Vector2((clientX - r.left) / r.width * 2 - 1,
      -(clientY - r.top) / r.height * 2 + 1);
    raycaster.params.Line.threshold = view.radius * 0.01;
    raycaster.setFromCamera(ndc, view.camera);
    const hit = raycaster.intersectObject(pane.mesh)[0];
    if (!hit) return null;
    const m = view.data.views[pane.model], d = m.decoded;
    const pos = pane.mesh.geometry.getAttribute('position');
    const candidates = hit.face ? [hit.face.a, hit.face.b, hit.face.c] : [d.idx[hit.index], d.idx[hit.index + 1]];
    let best = candidates[0], dist = Infinity;
    for (const k of candidates) {
      const dk = hit.point.distanceTo(new THREE.Vector3(pos.getX(k), pos.getY(k), pos.getZ(k)));
      if (dk < dist) { dist = dk; best = k; }
    }
    const vec = (a) => [a[3 * best], a[3 * best + 1], a[3 * best + 2]];
    return {model: modelName(m), node: best, colour_value: d.err[best] * m.step,
      u_model_mm: vec(d.um), u_reference_mm: vec(d.ur)};
  }
  report.nodeAt = nodeAt;

  function hover(view, pane, e) {
    const n = nodeAt(view, pane, e.clientX, e.clientY);
    if (!n) { tip.style.display = 'none'; return; }
    const v = (u) => '(' + u.map(fmt).join(', ') + ') mm, |u| ' + fmt(Math.hypot(u[0], u[1], u[2])) + ' mm';
    tip.textContent = n.model + ', node ' + n.node + '\n' + colourName(view) + ' ' +
      fmt(n.colour_value) + ' ' + colourUnit(view) + '\nmodel u ' + v(n.u_model_mm) +
      '\nreference u ' + v(n.u_reference_mm);
    Object.assign(tip.style, {display: 'block', left: (e.clientX + 14) + 'px', top: (e.clientY + 10) + 'px'});
  }

  function initView(section) {
    if (section.vvView) return section.vvView;
    const start = performance.now();
    ensureRenderer();
    const index = section.dataset.sceneIndex;
    const data = JSON.parse(document.getElementById('vv-scene-' + index).textContent);
    const view = {section: section, data: data, panes: [], ghost: -1, scaleMax: 0};
    section.vvView = view;
    data.views.forEach((m, i) => {
      view.scaleMax = Math.max(view.scaleMax, m.max);
      if (view.ghost < 0 || (m.nodes > data.views[view.ghost].nodes && !m.lines)) view.ghost = i;
    });
    if (view.scaleMax <= 0) view.scaleMax = data.tolerance_mm || 1;
    // Size and default magnification from the ghost: its largest reference displacement shown
    // as a tenth of the vessel's radius of gyration (at least true scale).
    const g = modelData(view, view.ghost).decoded;
    const box = new THREE.Box3().setFromArray(g.rest);
    view.centre = box.getCenter(new THREE.Vector3());
    view.radius = box.getSize(new THREE.Vector3()).length() / 2;
    let umax = 0;
    for (let i = 0; i < g.ur.length; i += 3) umax = Math.max(umax, Math.hypot(g.ur[i], g.ur[i + 1], g.ur[i + 2]));
    view.factor = umax > 0 && !data.true_scale ? Math.max(1, 0.1 * view.radius / umax) : 1;
    view.camera = new THREE.PerspectiveCamera(35, 1.5, view.radius * 0.01, view.radius * 20);
    view.fit = {centre: view.centre, radius: view.radius};  // until the models are shown
    // Looking at the QoI point's side of the vessel, a little from above and askew.
    view.orbit = {zoom: 1, theta: 0.9, phi: 1.1};
    if (data.qoi_mm) {
      const dx = data.qoi_mm[0] - view.centre.x, dy = data.qoi_mm[1] - view.centre.y;
      const dz = data.qoi_mm[2] - view.centre.z, d = Math.hypot(dx, dy, dz);
      if (d > 1e-9 * view.radius) {
        view.orbit.theta = Math.atan2(dx, dz) + 0.45;
        view.orbit.phi = Math.min(2.6, Math.max(0.5, Math.acos(dy / d) - 0.35));
      }
    }
    if (data.view_from) {  // a unit vector from the centre towards the camera, a little askew
      const v = data.view_from;
      view.orbit.theta = Math.atan2(v[0], v[2]) + 0.3;
      view.orbit.phi = Math.min(2.9, Math.max(0.25, Math.acos(Math.max(-1, Math.min(1, v[1]))) - 0.2));
    }
    section.querySelectorAll('.vv-pane').forEach((el) => view.panes.push({el: el}));
    view.panes.forEach((p) => buildPane(view, p));
    // Left: the most accurate model that is not FEM; right: P1 FEM when there, else the next.
    const order = data.views.map((m, i) => i).sort((a, b) => data.views[a].max - data.views[b].max);
    const left = order.find((i) => data.views[i].kind !== 'fem');
    const p1 = order.find((i) => data.views[i].kind === 'fem' && i !== left);
    const first = left === undefined ? order[0] : left;
    const second = p1 !== undefined ? p1 : order.find((i) => i !== first);
    section.querySelectorAll('.vv-pick').forEach((select, k) => {
      data.views.forEach((m, i) => {
        const o = document.createElement('option');
        o.value = i;
        o.textContent = modelName(m);
        select.appendChild(o);
      });
      const chosen = k === 0 ? first : (second === undefined ? first : second);
      select.value = chosen;
      select.addEventListener('change', () => showModel(view, view.panes[k], +select.value));
      showModel(view, view.panes[k], chosen);
    });
    const slider = section.querySelector('.vv-scale');
    slider.max = String(Math.max(3, Math.ceil(Math.log10(view.factor) + 1)));
    slider.value = String(Math.log10(view.factor));
    slider.addEventListener('input', () => setFactor(view, Math.pow(10, +slider.value)));
    setFactor(view, view.factor);
    const wireBox = section.querySelector('.vv-wire');
    if (wireBox) {
      wireBox.addEventListener('change', (e) => {
        view.panes.forEach((p) => {
          if (p.wire) p.wire.visible = e.target.checked;
          if (p.rigidWire) p.rigidWire.visible = e.target.checked;
        });
        requestRender();
      });
    }
    section.querySelector('.vv-ghost').addEventListener('change', (e) => {
      view.panes.forEach((p) => { if (p.ghost) p.ghost.visible = e.target.checked; });
      requestRender();
    });
    // Errors spanning more than a decade between the models: a log scale shows them all.
    const smallest = Math.min(...data.views.map((m) => m.max).filter((e) => e > 0));
    view.logScale = view.scaleMax > 10 * smallest;
    section.querySelector('.vv-log').checked = view.logScale;
    if (view.logScale) view.panes.forEach((p) => showModel(view, p, p.model));
    colourBar(view);
    section.querySelector('.vv-log').addEventListener('change', (e) => {
      view.logScale = e.target.checked;
      colourBar(view);
      view.panes.forEach((p) => showModel(view, p, p.model));
    });
    addOrbit(view);
    report.views.push(view);
    view.initMs = performance.now() - start;  // decoding, geometry, first draw requested
    return view;
  }
  report.initView = initView;

  function showInView(key) {
    const [scene, model, level] = key.split('|');
    const section = document.getElementById('view-' + scene);
    if (!section || !section.querySelector('.vv-pane')) return;
    const view = initView(section);
    const i = view.data.views.findIndex((m) => m.model === model && String(m.level) === level);
    if (i < 0) return;
    section.querySelector('.vv-pick[data-pane="0"]').value = i;
    showModel(view, view.panes[0], i);
    section.scrollIntoView({block: 'center'});
  }
  report.showInView = showInView;

  // ------------------------------------------------------------------------------- start --
  const plots = JSON.parse(document.getElementById('vv-plots').textContent);
  report.initChart = (box) => makeChart(box, plots[+box.dataset.plot], +box.dataset.plot);
  document.querySelectorAll('.vv-chart').forEach((box) => whenVisible(box, () => report.initChart(box)));
  document.querySelectorAll('.vv-view').forEach((section) => {
    if (section.querySelector('.vv-pane')) whenVisible(section, () => initView(section));
  });
  report.interactiveMs = performance.now();
})();
