// dvqp console: drawing the developed view, the cross-section and the heights on canvases.
// Plain script, no dependency. Lengths are metres, angles radians; l is arc length around
// the pipe (period 2πR), z the position along it, h the height above its surface.
"use strict";

const DvqpDraw = (function () {
  const TAU = 2 * Math.PI;
  const COPIES = [-1, 0, 1];
  const COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"];

  function fit(canvas) {
    const dpr = window.devicePixelRatio || 1;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr);
      canvas.height = Math.round(h * dpr);
    }
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, w, h);
    return { ctx, w, h };
  }

  function wrapArc(l, R) {
    const p = TAU * R;
    return l - p * Math.floor((l + p / 2) / p);
  }

  // Body points then the probe, [l, z, h], l continuous along the body, the first in [-πR, πR).
  function body(state, R) {
    const pts = state.points.map((p) => p.slice());
    pts.push(state.tool.slice(0, 3));
    for (let i = 1; i < pts.length; i++) {
      pts[i][0] = pts[i - 1][0] + wrapArc(pts[i][0] - pts[i - 1][0], R);
    }
    const shift = wrapArc(pts[0][0], R) - pts[0][0];
    pts.forEach((p) => { p[0] += shift; });
    return pts;
  }

  // An obstacle's outline moved to its copy nearest l = 0 (null for a band).
  function placed(obstacle, R) {
    if (obstacle.kind === "band" || obstacle.outline[0][0] === null) return null;
    const mean = obstacle.outline.reduce((s, p) => s + p[0], 0) / obstacle.outline.length;
    const shift = wrapArc(mean, R) - mean;
    return obstacle.outline.map((p) => [p[0] + shift, p[1]]);
  }

  function bandOf(obstacle) {
    return obstacle.z || [obstacle.outline[0][1], obstacle.outline[1][1]];
  }

  // Developed-view bounds {l0, l1, z0, z1} around the obstacles, the weld and a body.
  function initialBounds(scene, pts) {
    const b = { l0: Infinity, l1: -Infinity, z0: Infinity, z1: -Infinity };
    const R = scene.pipe_radius;
    for (const o of scene.obstacles) {
      const ring = placed(o, R);
      if (ring) ring.forEach((p) => include(b, p[0], p[1], R));
      else bandOf(o).forEach((z) => { b.z0 = Math.min(b.z0, z); b.z1 = Math.max(b.z1, z); });
    }
    if (scene.weld !== null) { b.z0 = Math.min(b.z0, scene.weld); b.z1 = Math.max(b.z1, scene.weld); }
    pts.forEach((p) => include(b, p[0], p[1], R));
    return b;
  }

  function include(b, l, z, R) {
    const pad = 0.05, edge = 1.12 * Math.PI * R;
    b.l0 = Math.max(-edge, Math.min(b.l0, l - pad));
    b.l1 = Math.min(edge, Math.max(b.l1, l + pad));
    b.z0 = Math.min(b.z0, z - pad);
    b.z1 = Math.max(b.z1, z + pad);
  }

  function niceStep(span, count) {
    const raw = span / count, mag = Math.pow(10, Math.floor(Math.log10(raw)));
    const n = raw / mag;
    return (n < 1.5 ? 1 : n < 3.5 ? 2 : n < 7.5 ? 5 : 10) * mag;
  }

  // A frame mapping data (x right, y up) into a margin box of the canvas, equal scales if asked.
  function frame(w, h, x0, x1, y0, y1, equal, margin) {
    const m = margin || { l: 46, r: 10, t: 8, b: 28 };
    let sx = (w - m.l - m.r) / (x1 - x0), sy = (h - m.t - m.b) / (y1 - y0);
    if (equal) { sx = sy = Math.min(sx, sy); }
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    const px = m.l + (w - m.l - m.r) / 2, py = m.t + (h - m.t - m.b) / 2;
    const f = {
      x: (x) => px + (x - cx) * sx, y: (y) => py - (y - cy) * sy, sx, sy, m, w, h,
      x0: cx - (px - m.l) / sx, x1: cx + (w - m.r - px) / sx,
      y0: cy - (h - m.b - py) / sy, y1: cy + (py - m.t) / sy,
    };
    return f;
  }

  // Tick label: fixed digits, never "-0.00".
  function tick(v, digits) {
    const text = v.toFixed(digits);
    return Number(text) === 0 ? (0).toFixed(digits) : text;
  }

  // Grid, tick labels and axis labels; digits: [x digits, y digits].
  function axes(ctx, f, xlabel, ylabel, digits) {
    ctx.save();
    ctx.strokeStyle = "#e6e8ee"; ctx.fillStyle = "#5c6475"; ctx.lineWidth = 1;
    ctx.font = "11px system-ui, sans-serif";
    const sx = niceStep(f.x1 - f.x0, 8), sy = niceStep(f.y1 - f.y0, 5);
    ctx.textAlign = "center"; ctx.textBaseline = "top";
    for (let x = Math.ceil(f.x0 / sx) * sx; x <= f.x1; x += sx) {
      line(ctx, f.x(x), f.m.t, f.x(x), f.h - f.m.b);
      ctx.fillText(tick(x, digits[0]), f.x(x), f.h - f.m.b + 3);
    }
    ctx.textAlign = "right"; ctx.textBaseline = "middle";
    for (let y = Math.ceil(f.y0 / sy) * sy; y <= f.y1; y += sy) {
      line(ctx, f.m.l, f.y(y), f.w - f.m.r, f.y(y));
      ctx.fillText(tick(y, digits[1]), f.m.l - 4, f.y(y));
    }
    ctx.textAlign = "right"; ctx.textBaseline = "bottom";
    ctx.fillText(xlabel, f.w - f.m.r, f.h - 1);
    ctx.save(); ctx.translate(11, f.m.t); ctx.rotate(-Math.PI / 2);
    ctx.fillText(ylabel, 0, 0); ctx.restore();
    ctx.restore();
  }

  function line(ctx, x0, y0, x1, y1) {
    ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
  }

  function polyline(ctx, f, pts, close) {
    ctx.beginPath();
    pts.forEach((p, i) => (i ? ctx.lineTo(f.x(p[0]), f.y(p[1])) : ctx.moveTo(f.x(p[0]), f.y(p[1]))));
    if (close) ctx.closePath();
  }

  function heightColor(dh) {
    const t = Math.max(-1, Math.min(1, dh / 0.02));
    const a = t < 0 ? [31, 119, 180] : [214, 39, 40], g = [110, 110, 110];
    const c = g.map((v, i) => Math.round(v + (a[i] - v) * Math.abs(t)));
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  function triangle(ctx, x, y, size, color) {
    ctx.fillStyle = color;
    ctx.beginPath();
    ctx.moveTo(x, y - size); ctx.lineTo(x - size * 0.87, y + size * 0.5);
    ctx.lineTo(x + size * 0.87, y + size * 0.5); ctx.closePath(); ctx.fill();
  }

  return { TAU, COPIES, COLORS, fit, wrapArc, body, placed, bandOf, initialBounds, include,
           frame, axes, line, polyline, heightColor, triangle };
})();
