// The live view: snapshots from ofn_viewer (GET /api/snapshot once, then the
// Server-Sent Events of /api/stream) drawn on two canvases. Snapshots are SI,
// world NED; the page shows lengths in the snapshot's display unit.
"use strict";

const COLOURS = {
  trail: "#1f5fbf", vehicle: "#000000", route: "#2a9d2a", plan: "#e07b00", stop: "#c0182a",
  obstacle: "rgba(122,122,122,0.45)", obstacleEdge: "#5a5a5a", cuboid: "#8e44ad",
  grid: "#c8b48c", waypoint: "#008b8b", axis: "#888888", background: "#fbfbf8", ground: "#8b6b3d",
  passage: "#c0182a",
};
const METRES_PER_FOOT = 0.3048;

let latest = null;       // newest snapshot
let frame = null;        // top-view bounds {n0, n1, e0, e1}, metres; only grows
let frameResets = -1;    // timeline_resets the frame belongs to
let drawPending = false;
let received = 0;

function unitScale(s) { return s.display_unit === "ft" ? 1 / METRES_PER_FOOT : 1; }
function fmt(value, digits) { return Number.isFinite(value) ? value.toFixed(digits) : "-"; }
function setText(id, text, stale) {
  const el = document.getElementById(id);
  el.textContent = text;
  el.classList.toggle("stale", !!stale);
}

// ---------------------------------------------------------------- frame
function extend(b, n, e) {
  if (!Number.isFinite(n) || !Number.isFinite(e)) return;
  b.n0 = Math.min(b.n0, n); b.n1 = Math.max(b.n1, n);
  b.e0 = Math.min(b.e0, e); b.e1 = Math.max(b.e1, e);
}

function obstacleCorners(o) {
  // Footprint outline (north, east); round obstacles as 24-gons.
  const pts = [];
  if (o.kind === "box") {
    const c = Math.cos(o.yaw), s = Math.sin(o.yaw), l = o.size[0] / 2, w = o.size[1] / 2;
    for (const [a, b] of [[l, w], [l, -w], [-l, -w], [-l, w]])
      pts.push([o.center[0] + a * c - b * s, o.center[1] + a * s + b * c]);
  } else {
    const r = o.size[0] / 2;
    for (let i = 0; i < 24; i++) {
      const t = (i / 24) * 2 * Math.PI;
      pts.push([o.center[0] + r * Math.cos(t), o.center[1] + r * Math.sin(t)]);
    }
  }
  return pts;
}

function updateFrame(s) {
  const resets = s.counters ? s.counters.timeline_resets : 0;
  if (resets !== frameResets) { frame = null; frameResets = resets; }
  const b = frame ? { ...frame } : { n0: Infinity, n1: -Infinity, e0: Infinity, e1: -Infinity };
  if (s.obstacles) for (const o of s.obstacles.list) for (const [n, e] of obstacleCorners(o)) extend(b, n, e);
  for (const c of s.cuboids) { extend(b, c.min[0], c.min[1]); extend(b, c.max[0], c.max[1]); }
  if (s.global_path) for (const p of s.global_path.points) extend(b, p[0], p[1]);
  if (s.mission) for (const p of s.mission.waypoints) extend(b, p[0], p[1]);
  for (const p of s.trail) extend(b, p[0], p[1]);
  if (s.vehicle) extend(b, s.vehicle.position[0], s.vehicle.position[1]);
  if (s.ref_traj) for (const p of s.ref_traj.positions) extend(b, p[0], p[1]);
  if (!Number.isFinite(b.n0)) return;
  frame = b;
}

function topTransform(canvas) {
  // Equal scales; north to the right, east up; 8 % margin.
  const pad = 40;
  const spanN = Math.max(frame.n1 - frame.n0, 10), spanE = Math.max(frame.e1 - frame.e0, 10);
  const midN = (frame.n0 + frame.n1) / 2, midE = (frame.e0 + frame.e1) / 2;
  const k = Math.min((canvas.width - 2 * pad) / (spanN * 1.08), (canvas.height - 2 * pad) / (spanE * 1.08));
  return {
    k,
    x: (n) => canvas.width / 2 + (n - midN) * k,
    y: (e) => canvas.height / 2 - (e - midE) * k,
    n0: midN - (canvas.width / 2) / k, n1: midN + (canvas.width / 2) / k,
    e0: midE - (canvas.height / 2) / k, e1: midE + (canvas.height / 2) / k,
  };
}

// ---------------------------------------------------------------- drawing
function niceStep(span) {
  const raw = span / 6, p = Math.pow(10, Math.floor(Math.log10(raw))), m = raw / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

function axes(ctx, canvas, lo, hi, toPx, vertical, scale, unit, label) {
  // Ticks every nice step of the display unit along one axis.
  ctx.save();
  ctx.strokeStyle = "#e4e4e0"; ctx.fillStyle = COLOURS.axis; ctx.font = "11px sans-serif";
  const step = niceStep((hi - lo) * scale);
  for (let v = Math.ceil(lo * scale / step) * step; v <= hi * scale; v += step) {
    const px = toPx(v / scale);
    ctx.beginPath();
    if (vertical) { ctx.moveTo(0, px); ctx.lineTo(canvas.width, px); ctx.stroke(); ctx.fillText(v.toFixed(0), 3, px - 2); }
    else { ctx.moveTo(px, 0); ctx.lineTo(px, canvas.height); ctx.stroke(); ctx.fillText(v.toFixed(0), px + 2, canvas.height - 4); }
  }
  ctx.fillText(label + " [" + unit + "]", vertical ? 3 : canvas.width - 80, vertical ? 12 : canvas.height - 16);
  ctx.restore();
}

function polyline(ctx, pts, colour, width, dash) {
  if (pts.length < 2) return;
  ctx.save();
  ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(dash || []);
  ctx.beginPath();
  ctx.moveTo(pts[0][0], pts[0][1]);
  for (const p of pts.slice(1)) ctx.lineTo(p[0], p[1]);
  ctx.stroke();
  ctx.restore();
}

function cross(ctx, x, y, colour) {
  ctx.save(); ctx.strokeStyle = colour; ctx.lineWidth = 2.5;
  ctx.beginPath(); ctx.moveTo(x - 6, y - 6); ctx.lineTo(x + 6, y + 6); ctx.moveTo(x - 6, y + 6); ctx.lineTo(x + 6, y - 6);
  ctx.stroke(); ctx.restore();
}

function drawTop(s) {
  const canvas = document.getElementById("top-view"), ctx = canvas.getContext("2d");
  ctx.fillStyle = COLOURS.background; ctx.fillRect(0, 0, canvas.width, canvas.height);
  if (!frame) return 0;
  const T = topTransform(canvas), scale = unitScale(s);
  axes(ctx, canvas, T.n0, T.n1, T.x, false, scale, s.display_unit, "north");
  axes(ctx, canvas, T.e0, T.e1, T.y, true, scale, s.display_unit, "east");
  if (s.grid) {
    ctx.fillStyle = COLOURS.grid;
    const w = Math.max(1, s.grid.resolution * T.k);
    for (const c of s.grid.cells) ctx.fillRect(T.x(c[0]) - w / 2, T.y(c[1]) - w / 2, w, w);
  }
  if (s.obstacles) for (const o of s.obstacles.list) {
    const pts = obstacleCorners(o);
    ctx.beginPath();
    ctx.moveTo(T.x(pts[0][0]), T.y(pts[0][1]));
    for (const p of pts.slice(1)) ctx.lineTo(T.x(p[0]), T.y(p[1]));
    ctx.closePath();
    ctx.fillStyle = COLOURS.obstacle; ctx.fill();
    ctx.strokeStyle = COLOURS.obstacleEdge; ctx.lineWidth = 1; ctx.stroke();
  }
  ctx.strokeStyle = COLOURS.cuboid; ctx.lineWidth = 1.5;
  for (const c of s.cuboids)
    ctx.strokeRect(T.x(c.min[0]), T.y(c.max[1]), (c.max[0] - c.min[0]) * T.k, (c.max[1] - c.min[1]) * T.k);
  // Passages too narrow to fly: the global planner routes round them.
  ctx.save(); ctx.strokeStyle = COLOURS.passage; ctx.lineWidth = 1.5; ctx.setLineDash([5, 3]);
  for (const p of s.narrow_passages || []) {
    ctx.beginPath(); ctx.arc(T.x(p.centre[0]), T.y(p.centre[1]), Math.max(3, p.radius * T.k), 0, 2 * Math.PI); ctx.stroke();
  }
  ctx.restore();
  if (s.mission) {
    ctx.strokeStyle = COLOURS.waypoint; ctx.lineWidth = 2;
    for (const w of s.mission.waypoints) { ctx.beginPath(); ctx.arc(T.x(w[0]), T.y(w[1]), 6, 0, 2 * Math.PI); ctx.stroke(); }
  }
  if (s.global_path)
    polyline(ctx, s.global_path.points.map((p) => [T.x(p[0]), T.y(p[1])]), COLOURS.route, 2, s.global_path.stale ? [4, 4] : []);
  polyline(ctx, s.trail.map((p) => [T.x(p[0]), T.y(p[1])]), COLOURS.trail, 2.5);
  if (s.ref_traj) {
    polyline(ctx, s.ref_traj.positions.map((p) => [T.x(p[0]), T.y(p[1])]), COLOURS.plan, 2.5, s.ref_traj.stale ? [4, 4] : []);
    const stop = s.ref_traj.safe_stop;
    if (stop) {
      polyline(ctx, [[T.x(stop.start[0]), T.y(stop.start[1])], [T.x(stop.point[0]), T.y(stop.point[1])]], COLOURS.stop, 2, [3, 3]);
      cross(ctx, T.x(stop.point[0]), T.y(stop.point[1]), COLOURS.stop);
    }
  }
  if (s.vehicle) {
    const x = T.x(s.vehicle.position[0]), y = T.y(s.vehicle.position[1]);
    const dn = Math.cos(s.vehicle.yaw), de = Math.sin(s.vehicle.yaw);
    const fx = dn, fy = -de, lx = de, ly = dn;  // forward and left in canvas pixels
    ctx.save(); ctx.fillStyle = COLOURS.vehicle; ctx.beginPath();
    ctx.moveTo(x + 12 * fx, y + 12 * fy);
    ctx.lineTo(x - 7 * fx + 6 * lx, y - 7 * fy + 6 * ly);
    ctx.lineTo(x - 7 * fx - 6 * lx, y - 7 * fy - 6 * ly);
    ctx.closePath(); ctx.fill(); ctx.restore();
  }
  return s.trail.length;
}

function drawProfile(s) {
  const canvas = document.getElementById("profile-view"), ctx = canvas.getContext("2d");
  ctx.fillStyle = COLOURS.background; ctx.fillRect(0, 0, canvas.width, canvas.height);
  if (!frame) return;
  const T = topTransform(document.getElementById("top-view")), scale = unitScale(s);
  const ground = s.obstacles ? s.obstacles.ground_altitude : 0;
  let top = ground + 10;
  const alt = (z) => -z;
  if (s.obstacles) for (const o of s.obstacles.list) top = Math.max(top, ground + o.height);
  for (const c of s.cuboids) top = Math.max(top, alt(c.min[2]));
  for (const p of s.trail) top = Math.max(top, alt(p[2]));
  if (s.ref_traj) for (const p of s.ref_traj.positions) top = Math.max(top, alt(p[2]));
  const bottom = Math.min(ground, 0), pad = 20;
  const ky = (canvas.height - 2 * pad) / ((top - bottom) * 1.1);
  const x = (n) => canvas.width / 2 + (n - (T.n0 + T.n1) / 2) * T.k;
  const y = (h) => canvas.height - pad - (h - bottom) * ky;
  axes(ctx, canvas, T.n0, T.n1, x, false, scale, s.display_unit, "north");
  axes(ctx, canvas, bottom, top * 1.1, y, true, scale, s.display_unit, "altitude");
  polyline(ctx, [[0, y(ground)], [canvas.width, y(ground)]], COLOURS.ground, 1.5);
  if (s.obstacles) for (const o of s.obstacles.list) {
    const pts = obstacleCorners(o), ns = pts.map((p) => p[0]);
    const n0 = Math.min(...ns), n1 = Math.max(...ns);
    ctx.fillStyle = COLOURS.obstacle;
    ctx.fillRect(x(n0), y(ground + o.height), (n1 - n0) * T.k, (o.height) * ky);
  }
  ctx.strokeStyle = COLOURS.cuboid; ctx.lineWidth = 1.5;
  for (const c of s.cuboids)
    ctx.strokeRect(x(c.min[0]), y(alt(c.min[2])), (c.max[0] - c.min[0]) * T.k, (c.max[2] - c.min[2]) * ky);
  if (s.global_path) polyline(ctx, s.global_path.points.map((p) => [x(p[0]), y(alt(p[2]))]), COLOURS.route, 2);
  polyline(ctx, s.trail.map((p) => [x(p[0]), y(alt(p[2]))]), COLOURS.trail, 2.5);
  if (s.ref_traj) {
    polyline(ctx, s.ref_traj.positions.map((p) => [x(p[0]), y(alt(p[2]))]), COLOURS.plan, 2.5);
    const stop = s.ref_traj.safe_stop;
    if (stop) cross(ctx, x(stop.point[0]), y(alt(stop.point[2])), COLOURS.stop);
  }
  if (s.vehicle) {
    ctx.fillStyle = COLOURS.vehicle; ctx.beginPath();
    ctx.arc(x(s.vehicle.position[0]), y(s.vehicle.altitude), 5, 0, 2 * Math.PI); ctx.fill();
  }
}

// ---------------------------------------------------------------- readouts
function readouts(s) {
  const scale = unitScale(s), u = s.display_unit;
  document.getElementById("mission-name").textContent = s.mission ? "- " + s.mission.name : "";
  const v = s.vehicle;
  setText("ro-time", v ? fmt(v.t, 1) + " s" : "-");
  setText("ro-mode", s.control ? s.control.mode + (s.control.ref_traj_fresh ? " (plan fresh)" : "") : "-", s.control && s.control.stale);
  setText("ro-speed", v ? fmt(v.speed * scale, 1) + " " + u + "/s" : "-");
  setText("ro-altitude", v ? fmt(v.altitude * scale, 1) + " " + u : "-");
  setText("ro-position", v ? fmt(v.position[0] * scale, 1) + " / " + fmt(v.position[1] * scale, 1) + " " + u : "-");
  const required = s.mission ? s.mission.limits.clearance : null;
  setText("ro-clearance", v && v.clearance !== null && v.clearance !== undefined
    ? fmt(v.clearance * scale, 1) + " " + u + " (" + v.clearance_to + ")" : "- (no VIRTUAL_OBSTACLES)",
    v && required !== null && v.clearance < required);
  setText("ro-required", required !== null ? fmt(required * scale, 1) + " " + u : "-");
  setText("ro-solver", s.solver ? s.solver.status + " (" + s.solver.iterations + " it)" : "-", s.solver && s.solver.stale);
  setText("ro-solve-time", s.solver ? fmt(s.solver.solve_time * 1000, 0) + " ms" : "-");
  setText("ro-plan", s.ref_traj ? s.ref_traj.mode + ", " + fmt(s.ref_traj.age, 1) + " s old" : "-", s.ref_traj && s.ref_traj.stale);
  const stop = s.ref_traj && s.ref_traj.safe_stop;
  setText("ro-stop", stop ? fmt(stop.distance * scale, 1) + " " + u + " in " + fmt(stop.time, 1) + " s" : "-");
  const narrow = (s.narrow_passages || []).length;
  setText("ro-route", (s.global_path ? s.global_path.status + ", " + s.global_path.points.length + " points" : "-") +
    (narrow ? ", " + narrow + " passage" + (narrow > 1 ? "s" : "") + " too narrow" : ""), s.global_path && s.global_path.stale);
  setText("ro-map", s.cuboids.length + " cuboids" + (s.grid ? ", " + s.grid.occupied + " grid cells" : ""));
  setText("ro-trail", s.trail.length + " points, " + fmt(s.trail_length * scale, 0) + " " + u);
  // The node's count includes the view's own (stamp order) rejections.
  const rejected = s.bus ? s.bus.rejected : s.counters.rejected_total;
  setText("ro-rejected", String(rejected) + (s.counters.last_rejection ? " (last: " + s.counters.last_rejection + ")" : ""));
  document.getElementById("solver-message").textContent = s.solver ? s.solver.message : "";
}

function draw() {
  drawPending = false;
  if (!latest) return;
  updateFrame(latest);
  const trailDrawn = drawTop(latest);
  drawProfile(latest);
  readouts(latest);
  document.body.dataset.snapshots = String(received);
  document.body.dataset.trailDrawn = String(trailDrawn);
}

function take(text) {
  try {
    latest = JSON.parse(text);
  } catch (e) {
    return;  // a torn or foreign message: keep the last good view
  }
  received += 1;
  if (!drawPending) { drawPending = true; requestAnimationFrame(draw); }
}

function connect() {
  const status = document.getElementById("connection");
  const stream = new EventSource("api/stream");
  stream.onopen = () => { status.textContent = "live"; status.classList.add("live"); };
  stream.onmessage = (event) => take(event.data);
  // EventSource reconnects by itself; say so meanwhile.
  stream.onerror = () => { status.textContent = "reconnecting"; status.classList.remove("live"); };
}

fetch("api/snapshot").then((r) => r.text()).then(take).catch(() => {}).finally(connect);
