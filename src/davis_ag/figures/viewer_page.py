"""The page ``davis-ag view`` serves: one HTML file with its style and script, no outside assets.

Keys follow the paper's actions: arrows or W/S/A/D move forward/backward/left/right, R and F
(or Page Up/Down) go up and down, Q and E rotate counter-clockwise and clockwise (MP scenes);
B, M, Z and O toggle the boxes, the instance masks, the depth image and the organ classes (Z
and O only where the scene has depth or class images). A click on the map jumps to that position at the current altitude,
keeping the heading nearest the current one. The address keeps ``#scene=...&view=...``, so a
view can be bookmarked. ``window.viewer`` exposes the state for tests.
"""

PAGE = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>DAVIS-Ag viewer</title>
<style>
body{font-family:sans-serif;margin:0;background:#1e1e1e;color:#eee}
header{padding:.5em 1em;background:#2b2b2b;display:flex;gap:1em;align-items:center;flex-wrap:wrap}
main{display:flex;gap:1em;padding:1em;align-items:flex-start;flex-wrap:wrap}
#stage{position:relative;width:min(960px,62vw);line-height:0;background:#000}
#stage img,#stage canvas{width:100%;image-rendering:pixelated}
#stage .layer{position:absolute;left:0;top:0}
#side{width:340px}
#map{background:#fafafa;border-radius:4px}
.hidden{display:none!important}
button.on{background:#4c9a3f;color:#fff}
kbd{background:#444;border-radius:3px;padding:0 4px}
#message{min-height:1.3em;color:#ffb347}
table{border-collapse:collapse;font-size:13px}td{padding:1px 6px}
.bad{color:#888}
</style></head>
<body>
<header>
  <b>DAVIS-Ag viewer</b>
  <label>scene <select id="scene-select"></select></label>
  <button id="boxes-toggle" class="on" title="B">boxes</button>
  <button id="mask-toggle" title="M">masks</button>
  <button id="depth-toggle" class="hidden" title="Z">depth</button>
  <button id="classes-toggle" class="hidden" title="O">organs</button>
  <span id="message"></span>
</header>
<main>
  <div>
    <div id="stage">
      <img id="photo" alt="view">
      <img id="depth" class="layer hidden" alt="depth">
      <img id="classes" class="layer hidden" alt="organ classes">
      <img id="mask" class="layer hidden" alt="instance mask">
      <canvas id="boxes" class="layer"></canvas>
    </div>
    <p><b id="view-name"></b> <span id="pose"></span> <span id="box-count"></span></p>
  </div>
  <div id="side">
    <svg id="map" width="340" height="340"></svg>
    <p>altitude <span id="altitude"></span></p>
    <table id="moves"></table>
    <p style="font-size:12px">
      <kbd>&uarr;</kbd>/<kbd>W</kbd> forward, <kbd>&darr;</kbd>/<kbd>S</kbd> backward,
      <kbd>&larr;</kbd>/<kbd>A</kbd> left, <kbd>&rarr;</kbd>/<kbd>D</kbd> right,
      <kbd>R</kbd>/<kbd>PgUp</kbd> up, <kbd>F</kbd>/<kbd>PgDn</kbd> down,
      <kbd>Q</kbd> rotate ccw, <kbd>E</kbd> rotate cw;
      <kbd>B</kbd> boxes, <kbd>M</kbd> masks, <kbd>Z</kbd> depth, <kbd>O</kbd> organs; click the map to jump.</p>
  </div>
</main>
<script>
"use strict";
const KEYS = {ArrowUp:"forward", w:"forward", ArrowDown:"backward", s:"backward",
  ArrowLeft:"left", a:"left", ArrowRight:"right", d:"right", r:"up", PageUp:"up",
  f:"down", PageDown:"down", q:"rotate_ccw", e:"rotate_cw"};
const viewer = window.viewer = {scene: null, view: null, data: null, path: [],
  layers: {boxes: true, mask: false, depth: false, classes: false}, moves: 0};
const $ = (id) => document.getElementById(id);
const enc = (id) => id.split("/").map(encodeURIComponent).join("/");
const esc = (text) => String(text).replace(/[&<>'"]/g, c => "&#" + c.charCodeAt(0) + ";");

function say(text) { $("message").textContent = text; }

async function getJSON(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(url + ": " + r.status + " " + await r.text());
  return r.json();
}

function parseHash() {
  const out = {};
  for (const part of location.hash.slice(1).split("&")) {
    const [k, v] = part.split("=");
    if (k) out[k] = decodeURIComponent(v || "");
  }
  return out;
}

async function loadScene(id, viewName) {
  viewer.data = await getJSON("/api/scene?id=" + encodeURIComponent(id));
  viewer.scene = id;
  viewer.path = [];
  $("scene-select").value = id;
  const hasDepth = Object.values(viewer.data.views).some(v => v.depth);
  $("depth-toggle").classList.toggle("hidden", !hasDepth);
  if (!hasDepth) viewer.layers.depth = false;
  const hasClasses = Object.values(viewer.data.views).some(v => v.classes);
  $("classes-toggle").classList.toggle("hidden", !hasClasses);
  if (!hasClasses) viewer.layers.classes = false;
  show(viewer.data.views[viewName] ? viewName : viewer.data.order[0]);
}

function level(z) { return Math.round(z * 100) / 100; }

function show(name) {
  const v = viewer.data.views[name];
  viewer.view = name;
  viewer.path.push(name);
  const base = enc(viewer.scene);
  $("photo").src = "/image/" + base + "/" + encodeURIComponent(name);
  $("mask").src = v.mask ? "/overlay/mask/" + base + "/" + encodeURIComponent(name) : "";
  $("depth").src = v.depth ? "/overlay/depth/" + base + "/" + encodeURIComponent(name) : "";
  $("classes").src = v.classes ? "/overlay/classes/" + base + "/" + encodeURIComponent(name) : "";
  $("view-name").textContent = viewer.scene + " " + name;
  $("pose").textContent = v.pose ? "pose x=" + v.pose[0].toFixed(3) + " y=" + v.pose[1].toFixed(3)
    + " z=" + v.pose[2].toFixed(2) + " yaw=" + v.pose[3].toFixed(0) + " pitch=" + v.pose[4].toFixed(1) : "no pose";
  $("box-count").textContent = v.boxes.length + " boxes";
  $("altitude").textContent = v.pose ? v.pose[2].toFixed(2) + " m (" +
    (viewer.data.altitudes.indexOf(level(v.pose[2])) + 1) + " of " + viewer.data.altitudes.length + ")" : "-";
  history.replaceState(null, "", "#scene=" + encodeURIComponent(viewer.scene) + "&view=" + encodeURIComponent(name));
  drawLayers();
  drawMoves();
  drawMap();
}

function drawLayers() {
  const v = viewer.data.views[viewer.view];
  $("mask").classList.toggle("hidden", !(viewer.layers.mask && v.mask));
  $("depth").classList.toggle("hidden", !(viewer.layers.depth && v.depth));
  $("classes").classList.toggle("hidden", !(viewer.layers.classes && v.classes));
  for (const k of ["boxes", "mask", "depth", "classes"]) $(k + "-toggle").classList.toggle("on", viewer.layers[k]);
  const photo = $("photo"), canvas = $("boxes");
  // The canvas has the displayed size, not the image's: boxes and labels stay crisp and
  // readable on small images scaled up.
  const paint = () => {
    const ratio = window.devicePixelRatio || 1;
    canvas.width = Math.round(photo.clientWidth * ratio); canvas.height = Math.round(photo.clientHeight * ratio);
    canvas.style.height = photo.clientHeight + "px";
    const g = canvas.getContext("2d"), s = canvas.width / photo.naturalWidth;
    g.clearRect(0, 0, canvas.width, canvas.height);
    if (!viewer.layers.boxes) return;
    g.lineWidth = 1.5 * ratio;
    g.font = (11 * ratio) + "px sans-serif";
    g.strokeStyle = "yellow"; g.fillStyle = "yellow";
    for (const [x, y, w, h, id] of v.boxes) {
      g.strokeRect(x * s, y * s, w * s, h * s);
      g.fillText(String(id), x * s, Math.max(y * s - 3 * ratio, 11 * ratio));
    }
  };
  viewer.repaint = paint;
  photo.onload = paint;
  if (photo.complete && photo.naturalWidth) paint();
}

function drawMoves() {
  const v = viewer.data.views[viewer.view];
  $("moves").innerHTML = viewer.data.actions.map(a => {
    const to = v.pointers[a];
    return "<tr class='" + (to ? "" : "bad") + "'><td>" + esc(a) + "</td><td>" + esc(to || "-") + "</td></tr>";
  }).join("");
}

function move(action) {
  const v = viewer.data.views[viewer.view];
  if (!(action in v.pointers)) { say(action + ": this scene has no such move"); return false; }
  const to = v.pointers[action];
  if (!to) { say(action + ": not possible from " + viewer.view); return false; }
  viewer.moves += 1;
  say(action + ": " + viewer.view + " -> " + to);
  show(to);
  return true;
}
viewer.move = move;

function drawMap() {
  const svg = $("map"), W = 340, pad = 18;
  const views = Object.entries(viewer.data.views).filter(([, v]) => v.pose);
  if (!views.length) { svg.innerHTML = ""; return; }
  const xs = views.map(([, v]) => v.pose[0]), ys = views.map(([, v]) => v.pose[1]);
  const plants = viewer.data.plants;
  const x0 = Math.min(...xs, ...plants.map(p => p[0])), x1 = Math.max(...xs, ...plants.map(p => p[0]));
  const y0 = Math.min(...ys, ...plants.map(p => p[1])), y1 = Math.max(...ys, ...plants.map(p => p[1]));
  const s = (W - 2 * pad) / Math.max(x1 - x0, y1 - y0, 1e-6);
  // Centred, one scale on both axes: an MP row (wide, shallow) stays in the middle.
  const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  const X = x => W / 2 + (x - cx) * s, Y = y => W / 2 - (y - cy) * s;
  const cur = viewer.data.views[viewer.view];
  const z = cur.pose ? level(cur.pose[2]) : null;
  const seen = new Set(); let html = "";
  for (const [name, v] of views) {
    if (level(v.pose[2]) !== z) continue;
    const key = v.pose[0].toFixed(3) + "," + v.pose[1].toFixed(3);
    if (seen.has(key)) continue;
    seen.add(key);
    html += "<circle class='spot' data-view='" + esc(name) + "' cx='" + X(v.pose[0]) + "' cy='" + Y(v.pose[1]) +
      "' r='5' fill='#9ab' stroke='#345' style='cursor:pointer'><title>" + esc(name) + "</title></circle>";
  }
  // Marks drawn over the spots let clicks through, so a spot under the path can still be clicked.
  for (const p of plants) html += "<text pointer-events='none' x='" + (X(p[0]) - 5) + "' y='" + (Y(p[1]) + 5) + "' font-size='16'>&#x2715;</text>";
  const trail = viewer.path.map(n => viewer.data.views[n].pose).filter(p => p);
  if (trail.length > 1) html += "<polyline pointer-events='none' fill='none' stroke='#1f77b4' stroke-width='2' points='" +
    trail.map(p => X(p[0]) + "," + Y(p[1])).join(" ") + "'/>";
  if (cur.pose) {
    const cx = X(cur.pose[0]), cy = Y(cur.pose[1]), yaw = cur.pose[3] * Math.PI / 180;
    html += "<line pointer-events='none' x1='" + cx + "' y1='" + cy + "' x2='" + (cx + 22 * Math.cos(yaw)) + "' y2='" +
      (cy - 22 * Math.sin(yaw)) + "' stroke='red' stroke-width='2'/>";
    html += "<rect id='current' pointer-events='none' x='" + (cx - 6) + "' y='" + (cy - 6) + "' width='12' height='12' fill='red' " +
      "transform='rotate(45 " + cx + " " + cy + ")'/>";
  }
  svg.innerHTML = html;
}

function jump(name) {
  const here = viewer.data.views[viewer.view].pose, there = viewer.data.views[name].pose;
  if (!here) { show(name); return; }
  let best = name, bestTurn = 1e9;
  for (const [n, v] of Object.entries(viewer.data.views)) {
    if (!v.pose || v.pose[0] !== there[0] || v.pose[1] !== there[1] || level(v.pose[2]) !== level(there[2])) continue;
    const turn = Math.abs(((v.pose[3] - here[3]) % 360 + 540) % 360 - 180);
    if (turn < bestTurn) { best = n; bestTurn = turn; }
  }
  say("jump: " + viewer.view + " -> " + best);
  show(best);
}

function toggle(layer) {
  if (layer === "depth" && $("depth-toggle").classList.contains("hidden")) { say("no depth images in this scene"); return; }
  if (layer === "classes" && $("classes-toggle").classList.contains("hidden")) { say("no organ class images in this scene"); return; }
  viewer.layers[layer] = !viewer.layers[layer];
  drawLayers();
}

document.addEventListener("keydown", (event) => {
  if (event.target.tagName === "SELECT" || event.ctrlKey || event.metaKey || event.altKey) return;
  const key = event.key.length === 1 ? event.key.toLowerCase() : event.key;
  if (KEYS[key]) { event.preventDefault(); move(KEYS[key]); }
  else if (key === "b") toggle("boxes");
  else if (key === "m") toggle("mask");
  else if (key === "z") toggle("depth");
  else if (key === "o") toggle("classes");
});
$("map").addEventListener("click", (event) => {
  const name = event.target.getAttribute && event.target.getAttribute("data-view");
  if (name) jump(name);
});
for (const k of ["boxes", "mask", "depth", "classes"]) $(k + "-toggle").addEventListener("click", () => toggle(k));
$("scene-select").addEventListener("change", (event) => loadScene(event.target.value));
window.addEventListener("resize", () => viewer.repaint && viewer.repaint());

(async () => {
  try {
    const list = await getJSON("/api/scenes");
    $("scene-select").innerHTML = list.scenes.map(s =>
      "<option value='" + esc(s.id) + "'>" + esc(s.id) + " (" + s.views + " views)</option>").join("");
    const wanted = parseHash();
    const ids = list.scenes.map(s => s.id);
    await loadScene(ids.includes(wanted.scene) ? wanted.scene : ids[0], wanted.view);
    viewer.ready = true;
  } catch (error) { say(String(error)); }
})();
</script>
</body></html>
"""
