// wavesph-plot: a minimal line chart on a <canvas>, no dependencies.
// SPDX-License-Identifier: MIT  (c) wavesph authors
// plot(canvas, series, opts): series = [{name, x: [...], y: [...]}]; null/NaN y break the line.
// scatter(canvas, particles, opts): the last snapshot's particles coloured by a value.
(function (global) {
  "use strict";
  const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"];

  function niceRange(lo, hi) {
    if (!isFinite(lo) || !isFinite(hi)) return [0, 1];
    if (hi - lo < 1e-12) { const d = Math.abs(hi) * 0.1 || 1; return [lo - d, hi + d]; }
    const pad = 0.05 * (hi - lo);
    return [lo - pad, hi + pad];
  }

  function plot(canvas, series, opts) {
    opts = opts || {};
    const ctx = canvas.getContext("2d");
    const W = canvas.width, H = canvas.height, L = 60, R = 110, T = 10, B = 30;
    ctx.clearRect(0, 0, W, H);
    let xlo = Infinity, xhi = -Infinity, ylo = Infinity, yhi = -Infinity, points = 0;
    for (const s of series) {
      for (let k = 0; k < s.x.length; k++) {
        const y = s.y[k];
        if (y === null || !isFinite(y)) continue;
        xlo = Math.min(xlo, s.x[k]); xhi = Math.max(xhi, s.x[k]);
        ylo = Math.min(ylo, y); yhi = Math.max(yhi, y); points++;
      }
    }
    [xlo, xhi] = niceRange(xlo, xhi);
    [ylo, yhi] = niceRange(ylo, yhi);
    const sx = (x) => L + (x - xlo) / (xhi - xlo) * (W - L - R);
    const sy = (y) => H - B - (y - ylo) / (yhi - ylo) * (H - T - B);
    ctx.strokeStyle = "#888"; ctx.fillStyle = "#333"; ctx.font = "11px sans-serif";
    ctx.strokeRect(L, T, W - L - R, H - T - B);
    for (let k = 0; k <= 4; k++) {
      const x = xlo + k / 4 * (xhi - xlo), y = ylo + k / 4 * (yhi - ylo);
      ctx.fillText(x.toPrecision(3), sx(x) - 12, H - B + 14);
      ctx.fillText(y.toPrecision(3), 2, sy(y) + 4);
    }
    if (opts.xlabel) ctx.fillText(opts.xlabel, W - R - 40, H - 2);
    if (opts.ylabel) ctx.fillText(opts.ylabel, 2, T + 10);
    series.forEach((s, i) => {
      ctx.strokeStyle = COLOURS[i % COLOURS.length];
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      let pen = false;
      for (let k = 0; k < s.x.length; k++) {
        const y = s.y[k];
        if (y === null || !isFinite(y)) { pen = false; continue; }
        if (pen) ctx.lineTo(sx(s.x[k]), sy(y)); else ctx.moveTo(sx(s.x[k]), sy(y));
        pen = true;
      }
      ctx.stroke();
      ctx.fillStyle = ctx.strokeStyle;
      ctx.fillText(s.name, W - R + 8, T + 14 + 14 * i);
    });
    canvas.dataset.points = String(points);  // for tests: how many points are drawn
    return points;
  }

  // scatter(canvas, {x, z, value, kind}, opts): particles at equal aspect; fluid and buffers
  // coloured by value (viridis-like, colour bar on the right), walls (kind 1) grey.
  const STOPS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  function colour(f) {
    f = Math.min(1, Math.max(0, f)) * (STOPS.length - 1);
    const i = Math.min(STOPS.length - 2, Math.floor(f)), u = f - i, a = STOPS[i], b = STOPS[i + 1];
    return "rgb(" + a.map((c, k) => Math.round(c + u * (b[k] - c))).join(",") + ")";
  }
  function scatter(canvas, d, opts) {
    opts = opts || {};
    const ctx = canvas.getContext("2d");
    const W = canvas.width, H = canvas.height, L = 50, R = 110, T = 10, B = 30;
    ctx.clearRect(0, 0, W, H);
    const n = d.x.length;
    let xlo = Infinity, xhi = -Infinity, zlo = Infinity, zhi = -Infinity, vlo = Infinity, vhi = -Infinity;
    for (let k = 0; k < n; k++) {
      xlo = Math.min(xlo, d.x[k]); xhi = Math.max(xhi, d.x[k]);
      zlo = Math.min(zlo, d.z[k]); zhi = Math.max(zhi, d.z[k]);
      if (d.kind[k] !== 1 && isFinite(d.value[k])) { vlo = Math.min(vlo, d.value[k]); vhi = Math.max(vhi, d.value[k]); }
    }
    if (!n) { canvas.dataset.points = "0"; return 0; }
    [vlo, vhi] = niceRange(vlo, vhi);
    // one scale for x and z: the tank's true shape
    const s = Math.min((W - L - R) / Math.max(xhi - xlo, 1e-9), (H - T - B) / Math.max(zhi - zlo, 1e-9));
    const px = (x) => L + (x - xlo) * s, pz = (z) => H - B - (z - zlo) * s;
    // a square per particle, about the spacing wide (from the area each particle covers)
    const r = Math.max(1.5, Math.min(8, 0.9 * s * Math.sqrt((xhi - xlo) * (zhi - zlo) / n)));
    for (let k = 0; k < n; k++) {
      ctx.fillStyle = d.kind[k] === 1 ? "#bbb" : colour((d.value[k] - vlo) / (vhi - vlo));
      ctx.fillRect(px(d.x[k]) - r / 2, pz(d.z[k]) - r / 2, r, r);
    }
    ctx.fillStyle = "#333"; ctx.font = "11px sans-serif";
    ctx.fillText(xlo.toPrecision(3) + " m", L, H - B + 14);
    ctx.fillText(xhi.toPrecision(3) + " m", px(xhi) - 30, H - B + 14);
    ctx.fillText(zhi.toPrecision(3) + " m", 2, pz(zhi) + 4);
    for (let j = 0; j < 100; j++) {  // colour bar
      ctx.fillStyle = colour(j / 99);
      ctx.fillRect(W - R + 20, H - B - (j + 1) * (H - T - B) / 100, 14, (H - T - B) / 100 + 1);
    }
    ctx.fillStyle = "#333";
    ctx.fillText(vhi.toPrecision(3), W - R + 38, T + 10);
    ctx.fillText(vlo.toPrecision(3), W - R + 38, H - B);
    if (opts.label) ctx.fillText(opts.label, W - R + 20, H - 4);
    canvas.dataset.points = String(n);  // for tests: how many particles are drawn
    return n;
  }

  global.wavesphPlot = plot;
  global.wavesphScatter = scatter;
})(window);
