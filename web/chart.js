// The error chart: the job's estimated error against time, log-log.
'use strict';

// The dashed guide: the relative MSE of an unbiased Monte Carlo estimate falls as 1/time (slope -1
// on log-log axes; its square root, the RMSE, would fall as 1/sqrt(time)). It runs through the
// latest point, where the ETA towards a target error extrapolates from (server/jobs.cpp), since
// the first passes' estimates run high (docs/performance.md, "Error estimate").
function errorGuide(points) {
  const last = points[points.length - 1];
  return { slope: -1, seconds: last.seconds, error: last.error };
}

function drawChart(canvas, points) {
  const dpr = window.devicePixelRatio || 1;
  const cw = canvas.clientWidth || 300, ch = canvas.clientHeight || 120;
  if (canvas.width !== Math.round(cw * dpr) || canvas.height !== Math.round(ch * dpr)) {
    canvas.width = Math.round(cw * dpr);
    canvas.height = Math.round(ch * dpr);
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, cw, ch);
  const css = getComputedStyle(document.documentElement);
  const muted = css.getPropertyValue('--muted').trim() || '#888';
  const grid = css.getPropertyValue('--line').trim() || '#333';
  const accent = css.getPropertyValue('--accent').trim() || '#f0a04b';
  ctx.font = '11px system-ui, sans-serif';
  const pts = points.filter((p) => p.seconds > 0 && p.error > 0);
  const L = 44, R = 10, T = 8, B = 20;
  const W = cw - L - R, H = ch - T - B;
  if (!pts.length) {
    ctx.fillStyle = muted;
    ctx.textAlign = 'center';
    ctx.fillText('the error estimate appears after the first passes', cw / 2, ch / 2);
    return;
  }
  const lx = pts.map((p) => Math.log10(p.seconds)), ly = pts.map((p) => Math.log10(p.error));
  // Log ranges padded a little around the data, at least one decade wide.
  const range = (vals) => {
    let lo = Math.min(...vals) - 0.08, hi = Math.max(...vals) + 0.08;
    if (hi - lo < 1) { const mid = (lo + hi) / 2; lo = mid - 0.5; hi = mid + 0.5; }
    return [lo, hi];
  };
  const [x0, x1] = range(lx), [y0, y1] = range(ly);
  const X = (v) => L + ((v - x0) / (x1 - x0)) * W;
  const Y = (v) => T + (1 - (v - y0) / (y1 - y0)) * H;
  const label = (v) => (v >= 1 ? String(Number(v.toPrecision(1))) : v.toPrecision(1));
  // Grid lines at 1..9 x 10^e; labels at 1, 2 and 5 x 10^e, thinned to what fits.
  const ticks = (lo, hi, maxLabels) => {
    const lines = [], labels = [];
    for (let e = Math.floor(lo); e <= Math.ceil(hi); ++e)
      for (let k = 1; k < 10; ++k) {
        const v = e + Math.log10(k);
        if (v < lo || v > hi) continue;
        lines.push({ v, major: k === 1 });
        if (k === 1 || k === 2 || k === 5) labels.push({ v, k, text: label(k * 10 ** e) });
      }
    let shown = labels;
    if (shown.length > maxLabels) shown = labels.filter((t) => t.k !== 2);
    if (shown.length > maxLabels) shown = labels.filter((t) => t.k === 1);
    return { lines, labels: shown };
  };

  ctx.strokeStyle = grid;
  ctx.lineWidth = 1;
  ctx.fillStyle = muted;
  const tx = ticks(x0, x1, Math.max(2, Math.floor(W / 60)));
  for (const t of tx.lines) {
    ctx.globalAlpha = t.major ? 1 : 0.35;
    ctx.beginPath(); ctx.moveTo(Math.round(X(t.v)) + 0.5, T); ctx.lineTo(Math.round(X(t.v)) + 0.5, T + H); ctx.stroke();
  }
  ctx.globalAlpha = 1;
  ctx.textAlign = 'center';
  for (const t of tx.labels) ctx.fillText(`${t.text} s`, Math.min(cw - 18, Math.max(L + 14, X(t.v))), ch - 5);
  const ty = ticks(y0, y1, Math.max(2, Math.floor(H / 22)));
  for (const t of ty.lines) {
    ctx.globalAlpha = t.major ? 1 : 0.35;
    ctx.beginPath(); ctx.moveTo(L, Math.round(Y(t.v)) + 0.5); ctx.lineTo(L + W, Math.round(Y(t.v)) + 0.5); ctx.stroke();
  }
  ctx.globalAlpha = 1;
  ctx.textAlign = 'right';
  for (const t of ty.labels) ctx.fillText(t.text, L - 6, Math.min(T + H, Math.max(T + 8, Y(t.v) + 4)));
  const guide = errorGuide(pts);
  const guideY = (x) => Math.log10(guide.error) + guide.slope * (x - Math.log10(guide.seconds));
  ctx.save();
  ctx.beginPath();
  ctx.rect(L, T, W, H);
  ctx.clip();
  ctx.setLineDash([4, 4]);
  ctx.strokeStyle = muted;
  ctx.beginPath();
  ctx.moveTo(X(x0), Y(guideY(x0)));
  ctx.lineTo(X(x1), Y(guideY(x1)));
  ctx.stroke();
  ctx.restore();

  ctx.strokeStyle = accent;
  ctx.fillStyle = accent;
  ctx.lineWidth = 2;
  ctx.beginPath();
  pts.forEach((p, i) => (i ? ctx.lineTo(X(lx[i]), Y(ly[i])) : ctx.moveTo(X(lx[i]), Y(ly[i]))));
  ctx.stroke();
  pts.forEach((p, i) => { ctx.beginPath(); ctx.arc(X(lx[i]), Y(ly[i]), 2.5, 0, 2 * Math.PI); ctx.fill(); });
}
