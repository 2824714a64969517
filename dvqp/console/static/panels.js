// dvqp console: the three panels (developed view, cross-section, heights), drawn from the
// scene message, the latest state and the recent history. Uses DvqpDraw (draw.js).
"use strict";

const DvqpPanels = (function () {
  const D = DvqpDraw;

  // The developed view; returns the probe's drawn position (canvas CSS pixels) and the
  // frame's visible extent {x0, x1, y0, y1} in (l, z), m.
  function developedView(canvas, scene, bounds, pts, trail, state) {
    const { ctx, w, h } = D.fit(canvas);
    const R = scene.pipe_radius, half = Math.PI * R;
    const f = D.frame(w, h, bounds.l0, bounds.l1, bounds.z0, bounds.z1, true);
    D.axes(ctx, f, "l (m)", "z (m)", [2, 2]);
    ctx.save();
    ctx.beginPath(); ctx.rect(f.m.l, f.m.t, w - f.m.l - f.m.r, h - f.m.t - f.m.b); ctx.clip();
    seams(ctx, f, half);
    obstacles(ctx, f, scene);
    if (scene.weld !== null) {
      ctx.strokeStyle = "#ff7f0e"; ctx.lineWidth = 1.5; ctx.setLineDash([7, 5]);
      D.line(ctx, f.m.l, f.y(scene.weld), w - f.m.r, f.y(scene.weld));
      ctx.setLineDash([]);
    }
    drawTrail(ctx, f, trail, R);
    let probe = null;
    for (const s of D.COPIES) {
      const shifted = pts.map((p) => [p[0] + s * 2 * half, p[1], p[2]]);
      const at = drawBody(ctx, f, shifted, scene.orbital_level, state.tool[3]);
      if (s === 0) probe = at;
    }
    ctx.restore();
    legend(ctx, f, scene);
    return { probe, visible: { x0: f.x0, x1: f.x1, y0: f.y0, y1: f.y1 } };
  }

  function seams(ctx, f, half) {
    ctx.fillStyle = "#dcdfe6";
    ctx.fillRect(f.x(-3 * half), f.m.t, f.x(-half) - f.x(-3 * half), f.h);
    ctx.fillRect(f.x(half), f.m.t, f.x(3 * half) - f.x(half), f.h);
    ctx.strokeStyle = "#6b7280"; ctx.lineWidth = 1;
    [-half, half].forEach((l) => D.line(ctx, f.x(l), 0, f.x(l), f.h));
  }

  function obstacles(ctx, f, scene) {
    const R = scene.pipe_radius;
    ctx.fillStyle = "rgba(214, 39, 40, 0.28)"; ctx.strokeStyle = "#8b1a1a"; ctx.lineWidth = 1;
    for (const o of scene.obstacles) {
      const ring = D.placed(o, R);
      if (!ring) {
        const [z0, z1] = D.bandOf(o);
        ctx.fillRect(0, f.y(z1), f.w, f.y(z0) - f.y(z1));
        D.line(ctx, 0, f.y(z0), f.w, f.y(z0)); D.line(ctx, 0, f.y(z1), f.w, f.y(z1));
        continue;
      }
      for (const s of D.COPIES) {
        D.polyline(ctx, f, ring.map((p) => [p[0] + s * D.TAU * R, p[1]]), true);
        ctx.fill(); ctx.stroke();
      }
    }
  }

  function drawTrail(ctx, f, trail, R) {
    if (trail.length < 2) return;
    ctx.lineWidth = 4; ctx.lineCap = "round";
    for (let i = 1; i < trail.length; i++) {
      const a = trail[i - 1], b = trail[i];
      if (Math.abs(b[0] - a[0]) > Math.PI * R) continue;  // crossed the seam
      ctx.strokeStyle = `rgba(0, 150, 136, ${(0.1 + 0.8 * i / trail.length).toFixed(3)})`;
      D.line(ctx, f.x(a[0]), f.y(a[1]), f.x(b[0]), f.y(b[1]));
    }
  }

  function drawBody(ctx, f, pts, hStar, alpha) {
    ctx.strokeStyle = "#23408e"; ctx.lineWidth = 2.2;
    D.polyline(ctx, f, pts, false); ctx.stroke();
    pts.slice(0, -1).forEach((p) => {
      ctx.fillStyle = D.heightColor(p[2] - hStar);
      ctx.beginPath(); ctx.arc(f.x(p[0]), f.y(p[1]), 4.5, 0, D.TAU); ctx.fill();
    });
    const tip = pts[pts.length - 1], x = f.x(tip[0]), y = f.y(tip[1]);
    ctx.strokeStyle = "#111"; ctx.lineWidth = 1.5;
    D.line(ctx, x, y, x + 16 * Math.cos(alpha), y - 16 * Math.sin(alpha));
    D.triangle(ctx, x, y, 7, "#111");
    return [x, y];
  }

  function legend(ctx, f, scene) {
    ctx.save();
    ctx.font = "11px system-ui, sans-serif"; ctx.textBaseline = "top"; ctx.textAlign = "left";
    const x = f.m.l + 6;
    let y = f.m.t + 4;
    const rows = [["#23408e", "body, probe ▲ with its heading α"],
                  ["#009688", "probe trail (last 3 s)"],
                  ["#d62728", "obstacle"],
                  ["#ff7f0e", scene.weld === null ? null : `weld z = ${scene.weld} m`],
                  ["#6e6e6e", `dots: h − h* (blue below, red above), h* = ${scene.orbital_level} m`]];
    for (const [color, text] of rows) {
      if (text === null) continue;
      ctx.fillStyle = "rgba(255,255,255,0.8)"; ctx.fillRect(x - 2, y - 1, ctx.measureText(text).width + 18, 14);
      ctx.fillStyle = color; ctx.fillRect(x, y + 3, 10, 6);
      ctx.fillStyle = "#1d2330"; ctx.fillText(text, x + 14, y);
      y += 14;
    }
    ctx.restore();
  }

  // The pipe's cross-section (x, y), the body at angle l/R and radius R + h.
  function crossSection(canvas, scene, pts) {
    const { ctx, w, h } = D.fit(canvas);
    const R = scene.pipe_radius, hStar = scene.orbital_level;
    const top = Math.max(hStar, ...pts.map((p) => p[2]), 0);
    const reach = R + top + 0.06 * R;
    const f = D.frame(w, h, -reach, reach, -reach, reach, true, { l: 40, r: 8, t: 6, b: 24 });
    D.axes(ctx, f, "x (m)", "y (m)", [2, 2]);
    const circle = (r, color, dash, width) => {
      ctx.strokeStyle = color; ctx.lineWidth = width; ctx.setLineDash(dash);
      ctx.beginPath(); ctx.arc(f.x(0), f.y(0), r * f.sx, 0, D.TAU); ctx.stroke(); ctx.setLineDash([]);
    };
    circle(R, "#1d2330", [], 1.6);
    circle(R + hStar, "#555", [6, 4], 1);
    if (scene.min_height) circle(R + scene.min_height, "#aaa", [2, 3], 1);
    ctx.strokeStyle = "rgba(214, 39, 40, 0.55)"; ctx.lineWidth = 6;
    for (const o of scene.obstacles) {
      const ring = D.placed(o, R);
      const lo = ring ? Math.min(...ring.map((p) => p[0])) : -Math.PI * R;
      const hi = ring ? Math.max(...ring.map((p) => p[0])) : Math.PI * R;
      ctx.beginPath(); ctx.arc(f.x(0), f.y(0), R * f.sx, -hi / R, -lo / R); ctx.stroke();
    }
    ctx.strokeStyle = "#6b7280"; ctx.lineWidth = 1;
    D.line(ctx, f.x(-0.85 * R), f.y(0), f.x(-reach), f.y(0));
    const xy = pts.map((p) => [(R + p[2]) * Math.cos(p[0] / R), (R + p[2]) * Math.sin(p[0] / R)]);
    ctx.strokeStyle = "#23408e"; ctx.lineWidth = 2; D.polyline(ctx, f, xy, false); ctx.stroke();
    const tip = xy[xy.length - 1];
    D.triangle(ctx, f.x(tip[0]), f.y(tip[1]), 6, "#111");
  }

  // Heights of the body points and the probe over the recent history [{t, h: [...]}, ...].
  function heights(canvas, scene, history, span) {
    const { ctx, w, h } = D.fit(canvas);
    if (!history.length) return;
    const t1 = history[history.length - 1].t, t0 = t1 - span;
    let lo = scene.orbital_level, hi = scene.orbital_level;
    history.forEach((e) => e.h.forEach((v) => { lo = Math.min(lo, v); hi = Math.max(hi, v); }));
    const pad = Math.max(0.002, 0.1 * (hi - lo));
    const f = D.frame(w, h, t0, t1, lo - pad, hi + pad, false, { l: 46, r: 74, t: 6, b: 24 });
    D.axes(ctx, f, "t (s)", "h (m)", [0, 3]);
    const level = (v, color, dash) => {
      ctx.strokeStyle = color; ctx.setLineDash(dash); ctx.lineWidth = 1;
      D.line(ctx, f.m.l, f.y(v), w - f.m.r, f.y(v)); ctx.setLineDash([]);
    };
    level(scene.orbital_level, "#555", [6, 4]);
    if (scene.min_height !== null && scene.min_height > f.y0) level(scene.min_height, "#b3261e", [2, 3]);
    const n = history[0].h.length;
    ctx.font = "11px system-ui, sans-serif"; ctx.textBaseline = "middle"; ctx.textAlign = "left";
    for (let i = 0; i < n; i++) {
      const probe = i === n - 1;
      ctx.strokeStyle = probe ? "#111" : D.COLORS[i % D.COLORS.length];
      ctx.lineWidth = probe ? 2 : 1.4;
      D.polyline(ctx, f, history.filter((e) => e.t >= t0).map((e) => [e.t, e.h[i]]), false);
      ctx.stroke();
      ctx.fillStyle = ctx.strokeStyle;
      ctx.fillText(probe ? "probe" : `point ${i + 1}`, w - f.m.r + 4, 12 + 13 * i);
    }
    ctx.fillStyle = "#555"; ctx.fillText("- - h*", w - f.m.r + 4, 12 + 13 * n);
  }

  return { developedView, crossSection, heights };
})();
