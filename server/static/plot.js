// wavesph-plot: a minimal line chart on a <canvas>, no dependencies.
// SPDX-License-Identifier: MIT  (c) wavesph authors
// plot(canvas, series, opts): series = [{name, x: [...], y: [...]}]; null/NaN y break the line.
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

  global.wavesphPlot = plot;
})(window);
