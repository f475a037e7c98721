"""The run viewer's page: one HTML file with its data, styles and script inline, no network.

`page(data)` takes `runner.output.viewerdata.Recorder.data()` and returns `viewer.html`, the data
inline as JSON that cannot end its `<script>` element (`escape.script_json`). The script inflates
the positions with the browser's `DecompressionStream`, then draws each frame the way
`engine.picture.raster` does: the background, then every object's sprite pixels in id order at its
rounded position, clipped to the world, into an ImageData at the world's size; that picture is
scaled by the zoom (whole factors, no smoothing) onto the canvas and the overlays are drawn over it.
At zoom 1 with every overlay off, the canvas holds exactly the PNG frame's pixels.

Controls: play / pause (space), one frame back and forward (left and right arrow keys, or the
buttons), the frame slider (Home / End), the speed, the zoom (also the mouse wheel) and panning
(drag the picture). The events list follows the frame (events of the current tick marked and
scrolled into view); clicking an event jumps to its tick and outlines the objects involved.
In a failing check's report, the golden's frames are a ghost over the run at their frames (on by
default; where a golden pixel differs from the run's, the mean of the two). Hovering an object
names it and shows its position (the rounded pixel position the frame draws it
at) and velocity (px/s) at the frame shown, following the frame as it plays. Overlays: velocity
arrows (half a second of motion), boxes (each object's pixel extent), contact flashes (a ring at
each object of a pair or wall event, fading over `FLASH_FRAMES` frames) and labels (not the frames'
`rests`: a run drawing it opens with the others it draws checked).
"""

from __future__ import annotations

import html

from collide2d.runner.output import escape

FLASH_FRAMES = 4
ZOOMS = (1, 2, 3, 4, 6, 8, 12, 16)
SPEEDS = (0.1, 0.25, 0.5, 1, 2, 4, 8)


def page(data: dict) -> bytes:
    title = f"collide2d viewer: {data['name']}"
    zooms = "".join(f'<option value="{z}">{z}x</option>' for z in ZOOMS)
    speeds = "".join(
        f'<option value="{s}"{" selected" if s == 1 else ""}>{s}x</option>' for s in SPEEDS
    )
    overlays = "".join(
        f'<label><input type="checkbox" id="ov-{key}"> {label}</label> '
        for key, label in (
            ("velocity", "velocity"),
            ("boxes", "boxes"),
            ("flashes", "contacts"),
            ("labels", "labels"),
            *((("overlap", "overlap before undo"),) if data["paper"] else ()),
        )
    )
    ghost = ""
    if data["ghostFrames"]:
        jumps = " ".join(
            f'<button type="button" class="ghost-frame" data-tick="{k}">{k}</button>'
            for k in data["ghostFrames"]
        )
        ghost = (
            '<p id="ghost-note"><label><input type="checkbox" id="ov-ghost" checked> golden '
            f'ghost</label> <span class="dim">at the golden\'s frames {jumps}: where the golden '
            "differs from this run, both are shown half and half</span></p>"
        )
    body = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width">
<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>
<header><b>{html.escape(data["name"])}</b> <span class="dim">{html.escape(data["model"])} model,
{data["width"]}x{data["height"]} px, {data["fps"]} fps, {len(data["names"])} objects</span></header>
<div id="controls">
<button type="button" id="back" title="one frame back (left arrow)">&#9664;&#9646;</button>
<button type="button" id="play" title="play / pause (space)">play</button>
<button type="button" id="fwd" title="one frame forward (right arrow)">&#9646;&#9654;</button>
<input type="range" id="seek" min="0" max="{data["frames"] - 1}" value="0" aria-label="frame">
<span id="tick">tick 0</span>
<label>speed <select id="speed">{speeds}</select></label>
<label>zoom <select id="zoom">{zooms}</select></label>
<span class="overlays">{overlays}</span>
</div>
{ghost}<div id="main"><div id="stage"><canvas id="view"></canvas></div>
<div id="side"><div id="hover" class="dim">hover an object to name it</div>
<div id="hover-state" class="dim"></div>
<h3>Events <span class="dim" id="event-count"></span></h3><ol id="events"></ol></div></div>
<p id="status" class="dim">loading…</p>
<script id="data" type="application/json">{escape.script_json(data)}</script>
<script>{_JS.replace("FLASH_FRAMES", str(FLASH_FRAMES))}</script>
</body></html>
"""
    return body.encode("utf-8")


_CSS = """
body { font: 14px/20px system-ui, sans-serif; margin: 16px; background: #f4f4f4; color: #222; }
header { height: 20px; overflow: hidden; }
.dim { color: #666; }
#controls { margin: 8px 0; height: 32px; display: flex; gap: 10px; align-items: center;
  white-space: nowrap; overflow: hidden; }
#controls button { min-width: 44px; height: 26px; }
#ghost-note { margin: 0 0 8px; } #ghost-note button { min-width: 32px; }
#seek { width: 300px; }
#main { display: flex; gap: 16px; align-items: flex-start; }
#stage { max-width: 960px; max-height: 720px; overflow: auto; border: 1px solid #999;
  background: #000; cursor: grab; }
#stage.dragging { cursor: grabbing; }
canvas { display: block; image-rendering: pixelated; }
#side { width: 320px; }
#side h3 { font-size: 14px; line-height: 20px; margin: 8px 0; }
#hover, #hover-state { height: 20px; overflow: hidden; white-space: nowrap; }
#events { height: 560px; overflow: auto; margin: 0; padding: 0 0 0 48px; background: #fff;
  border: 1px solid #ccc; font: 12px/16px ui-monospace, monospace; }
#events li { cursor: pointer; padding: 0 4px; }
#events li:hover { background: #eef; }
#events li.now { background: #ffe08a; }
#events li.selected { outline: 2px solid #c00; }
"""

_JS = r"""
(function () {
  "use strict";
  var D = JSON.parse(document.getElementById("data").textContent);
  var W = D.width, H = D.height, F = D.frames, N = D.names.length;
  var status = document.getElementById("status");
  var view = document.getElementById("view"), ctx = view.getContext("2d");
  var world = document.createElement("canvas");
  world.width = W; world.height = H;
  var wctx = world.getContext("2d");
  var image = wctx.createImageData(W, H);
  var pix = new Uint32Array(image.data.buffer);
  var seek = document.getElementById("seek"), tickText = document.getElementById("tick");
  var playBtn = document.getElementById("play"), zoomSel = document.getElementById("zoom");
  var speedSel = document.getElementById("speed"), list = document.getElementById("events");
  var hover = document.getElementById("hover"), stage = document.getElementById("stage");
  var hoverState = document.getElementById("hover-state"), hovered = -1;
  var ov = {};
  var named = {velocity: "velocity", boxes: "boxes", contacts: "flashes", labels: "labels",
               overlap: "overlap"};
  ["velocity", "boxes", "flashes", "labels", "overlap", "ghost"].forEach(function (k) {
    ov[k] = document.getElementById("ov-" + k) ||
      {checked: false, addEventListener: function () {}};
    ov[k].addEventListener("change", function () { draw(); });
  });
  // the frames' overlays it draws too (`rests` it does not)
  D.overlay.forEach(function (name) { if (named[name]) ov[named[name]].checked = true; });
  function rgba(c) { return ((255 << 24) | (c[2] << 16) | (c[1] << 8) | c[0]) >>> 0; }
  var bg = rgba(D.background);
  var col = D.colors.map(rgba);
  var pos = null, vel = null, off = null, ext = null, ghost = null, ghostAt = {};
  D.ghostFrames.forEach(function (k, g) { ghostAt[k] = g; });
  document.querySelectorAll("button.ghost-frame").forEach(function (b) {
    b.addEventListener("click", function () { setPlaying(false); go(Number(b.dataset.tick)); });
  });
  var frame = 0, zoom = 1, playing = false, selected = null;
  var byTick = {}, lit = [];

  function bytes(b64) {
    var s = atob(b64), out = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
    return out;
  }
  function inflate(b64) {
    var stream = new Blob([bytes(b64)]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Response(stream).arrayBuffer();
  }
  function undifference(a) {
    for (var i = 0; i < N; i++) {
      var base = i * F * 2;
      for (var k = 1; k < F; k++) {
        var p = base + k * 2;
        a[p] = (a[p] + a[p - 2]) | 0;
        a[p + 1] = (a[p + 1] + a[p - 1]) | 0;
      }
    }
    return a;
  }
  function extents() {
    var e = new Int32Array(N * 4), s = D.spriteStart;
    for (var i = 0; i < N; i++) {
      var x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
      for (var j = s[i]; j < s[i + 1]; j++) {
        x0 = Math.min(x0, off[2 * j]); x1 = Math.max(x1, off[2 * j]);
        y0 = Math.min(y0, off[2 * j + 1]); y1 = Math.max(y1, off[2 * j + 1]);
      }
      if (x1 < x0) { x0 = 0; y0 = 0; x1 = -1; y1 = -1; }
      e[4 * i] = x0; e[4 * i + 1] = y0; e[4 * i + 2] = x1; e[4 * i + 3] = y1;
    }
    return e;
  }
  function at(i, k) { var p = (i * F + k) * 2; return [pos[p], pos[p + 1]]; }

  function paint(k) {
    pix.fill(bg);
    var s = D.spriteStart;
    for (var i = 0; i < N; i++) {
      var p = (i * F + k) * 2, x = pos[p], y = pos[p + 1], c = col[i];
      for (var j = s[i]; j < s[i + 1]; j++) {
        var px = x + off[2 * j], py = y + off[2 * j + 1];
        if (px >= 0 && px < W && py >= 0 && py < H) pix[py * W + px] = c;
      }
    }
    if (ghost && ov.ghost.checked && ghostAt[k] !== undefined) blendGhost(ghostAt[k]);
    wctx.putImageData(image, 0, 0);
  }
  function blendGhost(g) {
    // the golden's frame g: where its pixel differs from the run's, the mean of the two
    var base = g * W * H * 3, d = image.data;
    for (var p = 0; p < W * H; p++) {
      var q = base + 3 * p, r = ghost[q], gg = ghost[q + 1], b = ghost[q + 2];
      if (d[4 * p] === r && d[4 * p + 1] === gg && d[4 * p + 2] === b) continue;
      d[4 * p] = (d[4 * p] + r) >> 1;
      d[4 * p + 1] = (d[4 * p + 1] + gg) >> 1;
      d[4 * p + 2] = (d[4 * p + 2] + b) >> 1;
    }
  }
  function centre(i, k) {
    var q = at(i, k);
    return [q[0] + (ext[4 * i] + ext[4 * i + 2] + 1) / 2,
            q[1] + (ext[4 * i + 1] + ext[4 * i + 3] + 1) / 2];
  }
  function outline(i, k, colour, width) {
    var q = at(i, k);
    ctx.strokeStyle = colour; ctx.lineWidth = width;
    ctx.strokeRect((q[0] + ext[4 * i]) * zoom - width / 2,
                   (q[1] + ext[4 * i + 1]) * zoom - width / 2,
                   (ext[4 * i + 2] - ext[4 * i] + 1) * zoom + width,
                   (ext[4 * i + 3] - ext[4 * i + 1] + 1) * zoom + width);
  }
  function overlays(k) {
    var i;
    if (ov.boxes.checked) for (i = 0; i < N; i++) outline(i, k, "rgba(0,200,255,0.9)", 1);
    if (ov.velocity.checked) {
      ctx.strokeStyle = "#ff0"; ctx.fillStyle = "#ff0"; ctx.lineWidth = 1.5;
      for (i = 0; i < N; i++) {
        var v = [vel[(i * F + k) * 2], vel[(i * F + k) * 2 + 1]];
        if (!v[0] && !v[1]) continue;
        var c = centre(i, k), x0 = c[0] * zoom, y0 = c[1] * zoom;
        var x1 = x0 + v[0] * 0.5 * zoom, y1 = y0 + v[1] * 0.5 * zoom;
        var a = Math.atan2(y1 - y0, x1 - x0), h = 4 + zoom;
        ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
        ctx.beginPath(); ctx.moveTo(x1, y1);
        ctx.lineTo(x1 - h * Math.cos(a - 0.5), y1 - h * Math.sin(a - 0.5));
        ctx.lineTo(x1 - h * Math.cos(a + 0.5), y1 - h * Math.sin(a + 0.5));
        ctx.closePath(); ctx.fill();
      }
    }
    if (ov.flashes.checked) {
      for (var back = 0; back < FLASH_FRAMES; back++) {
        (byTick[k - back] || []).forEach(function (li) {
          var e = D.events[li.dataset.index];
          var alpha = 1 - back / FLASH_FRAMES;
          ctx.strokeStyle = e[1] === 1 ? "rgba(255,96,0," + alpha + ")"
                                       : "rgba(255,230,0," + alpha + ")";
          ctx.lineWidth = 2;
          [e[2], e[3]].forEach(function (i) {
            if (i < 0) return;
            var c = centre(i, k);
            var side = Math.max(ext[4 * i + 2] - ext[4 * i], ext[4 * i + 3] - ext[4 * i + 1]);
            var r = (side / 2 + 3 + back * 2) * zoom;
            ctx.beginPath(); ctx.arc(c[0] * zoom, c[1] * zoom, r, 0, 2 * Math.PI); ctx.stroke();
          });
        });
      }
    }
    if (ov.labels.checked) {
      ctx.font = "11px sans-serif"; ctx.fillStyle = "#fff"; ctx.strokeStyle = "#000";
      ctx.lineWidth = 3;
      for (i = 0; i < N; i++) {
        var q = at(i, k), lx = (q[0] + ext[4 * i]) * zoom, ly = (q[1] + ext[4 * i + 1]) * zoom - 3;
        ctx.strokeText(D.names[i], lx, ly); ctx.fillText(D.names[i], lx, ly);
      }
    }
    if (ov.overlap.checked) {
      overlapRows.forEach(function (o) {
        if (o[0] !== k) return;
        ctx.setLineDash([3, 2]); ctx.strokeStyle = "#ccc"; ctx.lineWidth = 1;
        [[o[1], [o[9], o[10]]], [o[2], [o[11], o[12]]]].forEach(function (ip) {
          var i = ip[0], p = ip[1];
          ctx.strokeRect((p[0] + ext[4 * i]) * zoom + 0.5, (p[1] + ext[4 * i + 1]) * zoom + 0.5,
                         (ext[4 * i + 2] - ext[4 * i] + 1) * zoom - 1,
                         (ext[4 * i + 3] - ext[4 * i + 1] + 1) * zoom - 1);
        });
        ctx.setLineDash([]);
        var r = [o[5], o[6], o[7], o[8]];
        if (r[2] > r[0]) {
          ctx.fillStyle = "rgb(255,0,0)";
          ctx.fillRect(r[0] * zoom, r[1] * zoom, (r[2] - r[0]) * zoom, (r[3] - r[1]) * zoom);
        }
        ctx.font = "12px sans-serif"; ctx.fillStyle = "#fff";
        ctx.fillText("xdiff " + o[3] + ", ydiff " + o[4], (r[2] + 4) * zoom, (r[3] + 4) * zoom + 8);
      });
    }
    if (selected) {
      [selected[2], selected[3]].forEach(function (i) { if (i >= 0) outline(i, k, "#f0f", 2); });
    }
  }
  function draw() {
    if (!pos) return;
    paint(frame);
    if (view.width !== W * zoom || view.height !== H * zoom) {
      view.width = W * zoom; view.height = H * zoom;
    }
    ctx.imageSmoothingEnabled = false;
    ctx.clearRect(0, 0, view.width, view.height);
    ctx.drawImage(world, 0, 0, W * zoom, H * zoom);
    overlays(frame);
    seek.value = String(frame);
    tickText.textContent = "tick " + frame + " / " + (F - 1) + " · t = " +
      (frame / D.fps).toFixed(3) + " s";
    view.dataset.tick = String(frame);
    lit.forEach(function (li) { li.classList.remove("now"); });
    lit = byTick[frame] || [];
    lit.forEach(function (li) { li.classList.add("now"); });
    if (lit.length) list.scrollTop = lit[0].offsetTop - list.clientHeight / 3;
  }
  function go(k) { frame = Math.max(0, Math.min(F - 1, k | 0)); draw(); describe(); }
  function num(v) { return String(Math.round(v * 100) / 100); }
  function describe() {
    // the hovered object's name, rounded position (px) and velocity (px/s) at this frame
    var i = hovered;
    if (!pos || i < 0) {
      hover.textContent = "—"; hoverState.textContent = ""; view.title = "";
      return;
    }
    var q = at(i, frame), p = (i * F + frame) * 2;
    hover.textContent = D.names[i] + " (object " + i + (D.static[i] ? ", static" : "") + ")";
    hoverState.textContent = "at (" + q[0] + ", " + q[1] + ") px, velocity (" + num(vel[p]) +
      ", " + num(vel[p + 1]) + ") px/s";
    view.title = D.names[i];
  }
  function setPlaying(on) {
    playing = on && F > 1;
    playBtn.textContent = playing ? "pause" : "play";
    document.body.dataset.playing = playing ? "1" : "0";
    if (playing) {
      if (frame >= F - 1) go(0);
      last = null; acc = 0;
      requestAnimationFrame(loop);
    }
  }
  var last = null, acc = 0;
  function loop(now) {
    if (!playing) return;
    if (last !== null) acc += (now - last) / 1000 * D.fps * Number(speedSel.value);
    last = now;
    if (acc >= 1) {
      var step = Math.floor(acc); acc -= step;
      go(frame + step);
      if (frame >= F - 1) { setPlaying(false); return; }
    }
    requestAnimationFrame(loop);
  }
  function setZoom(z) { zoom = z; zoomSel.value = String(z); draw(); }

  var KINDS = ["wall", "pair", "rest", "stop", "wake", "leave"];  // engine/events.py TYPE_NAMES

  function buildEvents() {
    document.getElementById("event-count").textContent = D.eventCount > D.events.length
      ? "(first " + D.events.length + " of " + D.eventCount + ")" : "(" + D.eventCount + ")";
    var frag = document.createDocumentFragment();
    D.events.forEach(function (e, idx) {
      var li = document.createElement("li");
      li.dataset.index = String(idx);
      li.dataset.tick = String(e[0]);
      var kind = KINDS[e[1]] || "event";
      var who = e[1] === 1 ? D.names[e[2]] + " + " + D.names[e[3]]
        : D.names[e[2]] + (e[1] === 0 ? " wall" : "");
      li.textContent = "tick " + e[0] + ": " + kind + " " + who + " (" + e[4] + ")";
      li.addEventListener("click", function () {
        list.querySelectorAll("li.selected").forEach(function (o) {
          o.classList.remove("selected");
        });
        li.classList.add("selected");
        selected = e;
        setPlaying(false);
        go(e[0]);
      });
      (byTick[e[0]] = byTick[e[0]] || []).push(li);
      frag.appendChild(li);
    });
    list.appendChild(frag);
  }
  function objectAt(wx, wy) {
    for (var i = N - 1; i >= 0; i--) {
      var q = at(i, frame);
      if (wx >= q[0] + ext[4 * i] && wx <= q[0] + ext[4 * i + 2] &&
          wy >= q[1] + ext[4 * i + 1] && wy <= q[1] + ext[4 * i + 3]) return i;
    }
    return -1;
  }

  playBtn.addEventListener("click", function () { setPlaying(!playing); });
  document.getElementById("back").addEventListener("click", function () {
    setPlaying(false); go(frame - 1);
  });
  document.getElementById("fwd").addEventListener("click", function () {
    setPlaying(false); go(frame + 1);
  });
  seek.addEventListener("input", function () { setPlaying(false); go(Number(seek.value)); });
  zoomSel.addEventListener("change", function () { setZoom(Number(zoomSel.value)); });
  stage.addEventListener("wheel", function (e) {
    e.preventDefault();
    var zs = Array.prototype.map.call(zoomSel.options, function (o) { return Number(o.value); });
    var i = zs.indexOf(zoom) + (e.deltaY < 0 ? 1 : -1);
    if (i >= 0 && i < zs.length) setZoom(zs[i]);
  }, {passive: false});
  var drag = null;
  stage.addEventListener("mousedown", function (e) {
    drag = [e.clientX, e.clientY, stage.scrollLeft, stage.scrollTop];
    stage.classList.add("dragging");
  });
  window.addEventListener("mouseup", function () {
    drag = null; stage.classList.remove("dragging");
  });
  window.addEventListener("mousemove", function (e) {
    if (!drag) return;
    stage.scrollLeft = drag[2] - (e.clientX - drag[0]);
    stage.scrollTop = drag[3] - (e.clientY - drag[1]);
  });
  view.addEventListener("mousemove", function (e) {
    if (!pos) return;
    hovered = objectAt(Math.floor(e.offsetX / zoom), Math.floor(e.offsetY / zoom));
    describe();
  });
  view.addEventListener("mouseleave", function () { hovered = -1; describe(); });
  document.addEventListener("keydown", function (e) {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    var t = e.target && e.target.tagName;
    if (t === "INPUT" && e.target.type === "range") return;
    if (t === "SELECT") return;
    if (e.key === " ") setPlaying(!playing);
    else if (e.key === "ArrowRight") { setPlaying(false); go(frame + 1); }
    else if (e.key === "ArrowLeft") { setPlaying(false); go(frame - 1); }
    else if (e.key === "Home") { setPlaying(false); go(0); }
    else if (e.key === "End") { setPlaying(false); go(F - 1); }
    else return;
    e.preventDefault();
  });

  var fit = 1;
  [1, 2, 3, 4, 6, 8, 12, 16].forEach(function (z) { if (W * z <= 960 && H * z <= 720) fit = z; });
  var overlapRows = [];
  var loads = [inflate(D.positions), inflate(D.velocities), inflate(D.sprites),
               inflate(D.overlaps), inflate(D.ghost)];
  Promise.all(loads).then(function (bufs) {
    pos = undifference(new Int32Array(bufs[0]));
    vel = new Float32Array(bufs[1]);
    off = new Int32Array(bufs[2]);
    ghost = D.ghostFrames.length ? new Uint8Array(bufs[4]) : null;
    var flat = new Int32Array(bufs[3]);
    for (var r = 0; r + 13 <= flat.length; r += 13) overlapRows.push(flat.subarray(r, r + 13));
    ext = extents();
    buildEvents();
    setZoom(fit);
    status.textContent = F + " frames";
    document.body.dataset.ready = "1";
  }).catch(function (err) {
    status.textContent = "cannot read this viewer's data: " + err;
    console.error(err);
  });
})();
"""
