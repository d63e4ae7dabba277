// Injected at the top of a copy of report.html by report_browser_tests: records console errors,
// then, once the page has loaded, scrolls through it and writes what it found as JSON into
// <pre id="vv-probe"> for chromium --dump-dom: each 3D pane's pixels read back (those on its edge
// counted apart), each plot's points per series, the tooltip of a hovered point, and when the page
// became interactive.
(function () {
  'use strict';
  // chromium --dump-dom runs the page on virtual time and draws no frames, so animation frames
  // never come: timers stand in for them (Chart.js handles mouse events, and the page renders its
  // 3D views, in animation frames).
  window.requestAnimationFrame = (callback) => setTimeout(() => callback(performance.now()), 16);
  // Nor does it always run the IntersectionObserver that sets up a plot or a view scrolled into
  // sight: the probe sets each one up itself (the page's own set-up, the same code), so that a
  // view's first frame is the probe's to read.
  window.IntersectionObserver = class { observe() {} unobserve() {} disconnect() {} };
  const probe = {errors: []};
  const error = console.error;
  console.error = function () {
    probe.errors.push('console.error: ' + Array.from(arguments).join(' '));
    error.apply(console, arguments);
  };
  window.addEventListener('error', (e) => probe.errors.push('error: ' + e.message));
  window.addEventListener('unhandledrejection', (e) => probe.errors.push('rejection: ' + e.reason));
  const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

  function panePixels(gl, el) {
    const r = el.getBoundingClientRect();
    const w = Math.floor(r.width) - 4, h = Math.floor(r.height) - 4;
    const x = Math.ceil(r.left) + 2, y = Math.ceil(window.innerHeight - r.bottom) + 2;
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(x, y, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const colours = new Set();
    let drawn = 0, edge = 0;  // edge: drawn pixels on the outermost rows and columns read
    for (let i = 0; i < px.length; i += 4) {
      const background = px[i] === 246 && px[i + 1] === 246 && px[i + 2] === 246;
      const k = i / 4, col = k % w, row = Math.floor(k / w);
      if (!background) {
        ++drawn;
        if (col === 0 || col === w - 1 || row === 0 || row === h - 1) ++edge;
      }
      colours.add((px[i] << 16) | (px[i + 1] << 8) | px[i + 2]);
    }
    return {pixels: w * h, drawn: drawn, edge_drawn: edge, colours: colours.size, px: px};
  }

  // Two pane reads compared pixel by pixel: how many differ by more than a shading step.
  function differing(a, b) {
    if (a.pixels !== b.pixels) return {pixels: a.pixels, other_pixels: b.pixels, differing: a.pixels};
    let n = 0;
    for (let i = 0; i < a.px.length; i += 4) {
      if (Math.abs(a.px[i] - b.px[i]) + Math.abs(a.px[i + 1] - b.px[i + 1]) +
          Math.abs(a.px[i + 2] - b.px[i + 2]) > 12) ++n;
    }
    return {pixels: a.pixels, other_pixels: b.pixels, differing: n};
  }

  // Orange pixels (the wire's hue at any shading: red high, green about half of it, no blue).
  function orange(px) {
    let n = 0;
    for (let i = 0; i < px.length; i += 4) {
      const r = px[i], g = px[i + 1], b = px[i + 2];
      if (r > 100 && g > 0.35 * r && g < 0.7 * r && b < 0.15 * r) ++n;
    }
    return n;
  }

  // The wire's checkbox off and on again: the pixels of the left pane that change, and the
  // orange ones with and without the wire.
  function wireProbe(gl, view) {
    const box = view.section.querySelector('.vv-wire');
    if (!box) return null;
    const shot = () => { window.vvReport.renderNow(); return panePixels(gl, view.panes[0].el).px; };
    box.checked = false;
    box.dispatchEvent(new Event('change'));
    const off = shot();
    box.checked = true;
    box.dispatchEvent(new Event('change'));
    const on = shot();
    let changed = 0;
    for (let i = 0; i < on.length; i += 4) {
      if (on[i] !== off[i] || on[i + 1] !== off[i + 1] || on[i + 2] !== off[i + 2]) ++changed;
    }
    return {points: view.data.wire.rigid_mm.length, coupled: !!view.data.wire.coupled_mm,
      changed: changed, orange_on: orange(on), orange_off: orange(off)};
  }

  async function run() {
    const report = window.vvReport;
    const nav = performance.getEntriesByType('navigation')[0];
    const out = {errors: probe.errors, interactive_ms: report ? report.interactiveMs : null,
      dom_content_loaded_ms: nav ? nav.domContentLoadedEventEnd : null,
      load_ms: nav ? nav.loadEventEnd : null, views: [], charts: [], hover: null,
      node_hover: null};
    // Each plot and 3D view scrolled into view and set up; a view's first frame read at once.
    for (const el of document.querySelectorAll('.vv-chart, .vv-view')) {
      el.scrollIntoView({block: 'center'});
      await sleep(150);
      if (el.classList.contains('vv-chart')) report.initChart(el);
      else if (el.querySelector('.vv-pane')) {
        const view = report.initView(el);
        report.renderNow();
        view.firstFrame = view.panes.map((p) => Object.assign(panePixels(report.gl, p.el),
          {model: view.data.views[p.model].model}));
      }
    }
    for (const view of report.views) {
      view.section.scrollIntoView({block: 'center'});
      await sleep(200);
      report.renderNow();
      const gl = report.gl;
      const entry = {scene: view.data.name, init_ms: view.initMs, models: [],
        panes: view.firstFrame};
      // The right pane's model in the left pane too: one camera, one model, the same picture.
      const right = view.panes[1].model;
      view.section.querySelector('.vv-pick[data-pane="0"]').value = String(right);
      view.section.querySelector('.vv-pick[data-pane="0"]').dispatchEvent(new Event('change'));
      report.renderNow();
      entry.twin = Object.assign(differing(panePixels(gl, view.panes[0].el),
        panePixels(gl, view.panes[1].el)), {model: view.data.views[right].model});
      // Every model through the left pane's picker, as a reader would choose it.
      const pick = view.section.querySelector('.vv-pick[data-pane="0"]');
      for (let i = 0; i < view.data.views.length; ++i) {
        pick.value = String(i);
        pick.dispatchEvent(new Event('change'));
        report.renderNow();
        entry.models.push(Object.assign(panePixels(gl, view.panes[0].el),
          {model: view.data.views[i].model, springs: view.data.views[i].springs}));
      }
      entry.wire = wireProbe(gl, view);
      entry.panes.forEach((p) => delete p.px);
      entry.models.forEach((p) => delete p.px);
      out.views.push(entry);
      if (!out.node_hover) {
        const r = view.panes[0].el.getBoundingClientRect();
        for (let k = 0; k < 400 && !out.node_hover; ++k) {  // a spiral from the centre
          const a = k * 0.5, d = k * 0.4;
          out.node_hover = report.nodeAt(view, view.panes[0], r.left + r.width / 2 + d * Math.cos(a),
            r.top + r.height / 2 + d * Math.sin(a));
        }
      }
    }
    for (const c of report.charts) {
      out.charts.push({index: c.index, title: c.title, series: c.chart.data.datasets.map((d) => ({
        label: d.label, points: d.data.length, labelled: d.data.filter((p) => p.label).length}))});
    }
    // Hover the first labelled point of the first plot that has one: a real mouse move at its place.
    for (const c of report.charts) {
      const chart = c.chart;
      const d = chart.data.datasets.findIndex((s) => s.data.some((p) => p.label));
      if (d < 0) continue;
      chart.canvas.scrollIntoView({block: 'center'});
      await sleep(150);
      const el = chart.getDatasetMeta(d).data[0];
      const r = chart.canvas.getBoundingClientRect();
      chart.canvas.dispatchEvent(new MouseEvent('mousemove', {clientX: r.left + el.x,
        clientY: r.top + el.y, bubbles: true}));
      await sleep(200);
      const lines = (chart.tooltip.body || []).map((b) => b.lines.join(' '));
      out.hover = {plot: c.title, dataset: chart.data.datasets[d].label,
        visible: chart.tooltip.opacity > 0, text: lines.join(' | ')};
      break;
    }
    const pre = document.createElement('pre');
    pre.id = 'vv-probe';
    pre.textContent = JSON.stringify(out);
    document.body.appendChild(pre);
  }
  window.addEventListener('load', () => {
    setTimeout(() => run().catch((e) => {
      probe.errors.push('probe: ' + e);
      const pre = document.createElement('pre');
      pre.id = 'vv-probe';
      pre.textContent = JSON.stringify({errors: probe.errors});
      document.body.appendChild(pre);
    }), 50);
  });
})();
