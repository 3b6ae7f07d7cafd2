// The browser side of the report's scene player: unpacks what report_player.cpp packs
// (base64, then DecompressionStream('deflate'), then varints and deltas) and plays it
// on a <canvas>. Inline in the page: no network, no library.
//
// Page hash options (for links, screenshots and the browser test):
//   #only=NAME   show only that scenario's player (a screenshot of it);
//   t=SECONDS    start there;
//   play         start playing at once (data-fps on each player: frames drawn per second);
//   selftest     draw every frame of every player once, then set on <html>
//                data-player-status="ok" and data-players=N, and on each player
//                data-frames-drawn, data-bodies-drawn (most bodies of one source in the
//                last frame), data-ink (pixels that are not background) and
//                data-barrier-ink (the near-black pixels barriers are drawn with).
// Any script error is recorded on <html> as data-script-errors by a handler installed
// first, in its own <script>, so even a syntax error in the player shows.
#include "report_player.hpp"

namespace physval::report_detail {

std::string player_head() {
  return R"(<script>
window.physvalErrors = [];
(function () {
  function note(message) {
    window.physvalErrors.push(String(message));
    document.documentElement.setAttribute('data-script-errors', window.physvalErrors.join(' | '));
  }
  window.addEventListener('error', function (e) { note((e.message || 'error') + ' at ' + (e.filename || '') + ':' + (e.lineno || 0)); });
  window.addEventListener('unhandledrejection', function (e) { note('unhandled rejection: ' + (e.reason && e.reason.stack || e.reason)); });
})();
</script>
<style>
.player { margin: 1em 0; border: 1px solid #ddd; padding: 0.6em; background: #fafafa; }
.player canvas { display: block; background: #fff; border: 1px solid #e4e4e4; max-width: 100%; cursor: pointer; }
.player .pl-controls { margin: 0.5em 0; display: flex; flex-wrap: wrap; gap: 0.6em; align-items: center; font-size: 0.9em; }
.player .pl-controls input[type=range] { flex: 1 1 260px; }
.player button { min-width: 5.5em; }
.player .pl-time { font-variant-numeric: tabular-nums; min-width: 11em; }
.player table { margin: 0.3em 0; }
.player .swatch { display: inline-block; width: 1.6em; height: 0.8em; vertical-align: middle; margin-right: 0.3em; }
.player .pl-error { color: #b3261e; font-weight: 600; }
</style>
)";
}

std::string player_script() {
  return R"JS(<script>
(function () {
'use strict';
const params = new URLSearchParams(location.hash.slice(1));
const selftest = params.has('selftest');
const only = params.get('only');
const startAt = params.has('t') ? parseFloat(params.get('t')) : null;
const autoplay = params.has('play');
const SPEEDS = [0.01, 0.1, 0.25, 0.5, 1, 2, 5, 10, 30, 100, 300, 1000];

function bytesOf(text) {
  const bin = atob(text.trim());
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

async function inflate(bytes) {
  if (typeof DecompressionStream === 'undefined') {
    throw new Error('this browser has no DecompressionStream, which the player needs to unpack its data');
  }
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

// The layout is described at the top of report_player.cpp.
function decode(h, u) {
  let p = 0;
  function varint() {
    let v = 0, mul = 1, b;
    do {
      if (p >= u.length) throw new Error('player data for ' + h.scenario + ' ends early');
      b = u[p++];
      v += (b & 127) * mul;
      mul *= 128;
    } while (b & 128);
    return v;
  }
  const unzig = (z) => (z % 2 ? -(z + 1) / 2 : z / 2);
  const N = h.frames, B = h.bodies.length, q = h.quantum;
  const view = new DataView(u.buffer, u.byteOffset, u.byteLength);
  const out = [];
  for (let s = 0; s < h.sources.length; s++) {
    const pos = new Float32Array(B * N * 2);   // metres from the origin; NaN: not there
    for (let b = 0; b < B; b++) {
      let qx = 0, qy = 0;
      for (let k = 0; k < N; k++) {
        const cx = varint(), cy = varint(), i = (b * N + k) * 2;
        if (cx === 0 || cy === 0) { pos[i] = NaN; pos[i + 1] = NaN; continue; }
        qx += unzig(cx - 1);
        qy += unzig(cy - 1);
        pos[i] = qx * q;
        pos[i + 1] = qy * q;
      }
    }
    const energy = new Float64Array(N);
    for (let k = 0; k < N; k++) { energy[k] = view.getFloat32(p, true); p += 4; }
    const n = varint();
    const ca = new Int32Array(n), cb = new Int32Array(n), ct = new Float64Array(n);
    let tick = 0;
    for (let i = 0; i < n; i++) {
      ca[i] = varint();
      cb[i] = varint();
      tick += varint();
      ct[i] = tick / h.contact_ticks * h.duration;
    }
    const e0 = h.sources[s].e0 === null ? NaN : h.sources[s].e0;
    out.push({ pos, energy, e0, ca, cb, ct });
  }
  if (p !== u.length) throw new Error('player data for ' + h.scenario + ' has ' + (u.length - p) + ' bytes left over');
  return out;
}

// The number of sorted values <= x.
function countUpTo(sorted, x) {
  let lo = 0, hi = sorted.length;
  while (lo < hi) { const mid = (lo + hi) >> 1; if (sorted[mid] <= x) lo = mid + 1; else hi = mid; }
  return lo;
}

function fmt(v, digits) {
  if (!isFinite(v)) return '\u2013';
  if (v === 0) return '0';
  const a = Math.abs(v);
  return a >= 1e-3 && a < 1e4 ? v.toPrecision(digits || 3) : v.toExponential((digits || 3) - 1);
}

function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = text;
  return e;
}

class Player {
  constructor(root) {
    this.root = root;
    this.h = JSON.parse(root.querySelector('.player-header').textContent);
    this.dataText = root.querySelector('.player-data').textContent;
    this.framesDrawn = 0;
    this.playing = false;
    this.frame = -1;
    this.t = 0;
  }

  async load() {
    const h = this.h;
    this.data = decode(h, await inflate(bytesOf(this.dataText)));
    this.dataText = null;
    this.shown = h.sources.map(() => true);
    this.build();
    const d = h.duration;
    // Real time, unless that would take over 20 s: then fast enough to play in about 20 s.
    this.speed = SPEEDS[SPEEDS.length - 1];
    for (const s of SPEEDS) { if (s >= 1 && d <= 20 * s) { this.speed = s; break; } }
    this.speedSelect.value = String(this.speed);
    this.show(startAt !== null && isFinite(startAt) ? Math.min(Math.max(startAt, 0), d) : 0);
  }

  build() {
    const h = this.h, root = this.root;
    for (const n of root.querySelectorAll('p.note')) n.remove();
    this.canvas = el('canvas', { role: 'img', 'aria-label': h.scenario + ': bodies and barriers, engines overlaid on the reference' });
    root.appendChild(this.canvas);
    const controls = el('div', { class: 'pl-controls' });
    this.button = el('button', { type: 'button' }, '\u25B6 play');
    this.button.addEventListener('click', () => this.toggle());
    this.canvas.addEventListener('click', () => this.toggle());
    this.slider = el('input', { type: 'range', min: '0', max: String(h.frames - 1), step: '1', value: '0', 'aria-label': 'time' });
    this.slider.addEventListener('input', () => {
      this.pause();
      this.show(h.duration * Number(this.slider.value) / (h.frames - 1));
    });
    this.timeText = el('span', { class: 'pl-time' });
    const speedLabel = el('label', {}, 'speed ');
    this.speedSelect = el('select');
    for (const s of SPEEDS) this.speedSelect.appendChild(el('option', { value: String(s) }, s + '\u00d7'));
    this.speedSelect.addEventListener('change', () => { this.speed = Number(this.speedSelect.value); });
    speedLabel.appendChild(this.speedSelect);
    controls.append(this.button, this.slider, this.timeText, speedLabel);
    root.appendChild(controls);

    const table = el('table');
    const head = el('tr');
    for (const c of ['', 'shown', 'energy E(t) \u2212 E(0) (J)', 'relative to |E(0)|', 'contacts begun so far']) head.appendChild(el('th', {}, c));
    table.appendChild(head);
    this.cells = [];
    h.sources.forEach((s, i) => {
      const tr = el('tr');
      const name = el('td');
      const sw = el('span', { class: 'swatch' });
      sw.style.background = s.colour;
      if (s.engine) { sw.style.background = 'none'; sw.style.border = '2px solid ' + s.colour; }
      name.append(sw, document.createTextNode(s.label));
      const box = el('input', { type: 'checkbox', 'aria-label': 'show ' + s.label });
      box.checked = true;
      box.addEventListener('change', () => { this.shown[i] = box.checked; this.draw(this.frame, true); });
      const shownCell = el('td');
      shownCell.appendChild(box);
      const de = el('td', { class: 'num' }), rel = el('td', { class: 'num' }), nc = el('td', { class: 'num' });
      tr.append(name, shownCell, de, rel, nc);
      table.appendChild(tr);
      this.cells.push({ de, rel, nc });
    });
    root.appendChild(table);
    const counts = h.sources.map((s, i) => s.label + ' ' + this.data[i].ct.length).join(', ');
    root.appendChild(el('p', { class: 'note' },
      'Filled grey: the reference; rings: each engine in its colour (one ring a little wider than the next, so engines ' +
      'that agree show as concentric rings). Dark lines: walls, surfaces and boxes. A ring flashes where a contact ' +
      'begins (contacts in this run: ' + counts + '). Click the scene or press play; drag the slider to scrub.'));
    this.layout();
  }

  layout() {
    const h = this.h;
    const [x0, y0, x1, y1] = h.extent;
    const spanX = Math.max(x1 - x0, 1e-12), spanY = Math.max(y1 - y0, 1e-12);
    const width = Math.max(320, Math.min(1000, (this.root.clientWidth || 900) - 16));
    const height = Math.round(Math.min(560, Math.max(220, width * spanY / spanX)));
    const ratio = window.devicePixelRatio || 1;
    this.canvas.width = Math.round(width * ratio);
    this.canvas.height = Math.round(height * ratio);
    this.canvas.style.width = width + 'px';
    this.canvas.style.height = height + 'px';
    this.ctx = this.canvas.getContext('2d');
    this.ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    const margin = 14;
    this.scale = Math.min((width - 2 * margin) / spanX, (height - 2 * margin - 16) / spanY);
    // Positions are metres from the origin (the extent's lower left corner).
    this.offX = (width - this.scale * spanX) / 2;
    this.offY = height - (height - 16 - this.scale * spanY) / 2;
    this.width = width;
    this.height = height;
  }

  px(x) { return this.offX + x * this.scale; }
  py(y) { return this.offY - y * this.scale; }

  toggle() { if (this.playing) this.pause(); else this.play(); }

  play() {
    if (this.t >= this.h.duration) this.show(0);
    this.playing = true;
    this.button.textContent = '\u23F8 pause';
    let last = performance.now();
    const began = last, drawnBefore = this.framesDrawn;
    const step = (now) => {
      if (!this.playing) return;
      if (now > began) {   // how fast it plays here: drawn frames per second of wall time
        this.root.setAttribute('data-fps', ((this.framesDrawn - drawnBefore) / ((now - began) / 1000)).toFixed(1));
      }
      this.t = Math.min(this.h.duration, this.t + (now - last) / 1000 * this.speed);
      last = now;
      this.show(this.t);
      if (this.t >= this.h.duration) { this.pause(); return; }
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }

  pause() {
    this.playing = false;
    this.button.textContent = this.t >= this.h.duration ? '\u21BA replay' : '\u25B6 play';
  }

  show(t) {
    const h = this.h;
    this.t = t;
    const k = h.duration > 0 ? Math.round(t / h.duration * (h.frames - 1)) : 0;
    this.draw(Math.min(Math.max(k, 0), h.frames - 1), false);
  }

  draw(k, force) {
    const h = this.h, ctx = this.ctx;
    if (k === this.frame && !force) return;
    this.frame = k;
    const N = h.frames, B = h.bodies.length;
    const frameDt = N > 1 ? h.duration / (N - 1) : 0;
    const t = k * frameDt;
    const ox = h.origin[0], oy = h.origin[1];
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(0, 0, this.width, this.height);

    // Barriers.
    ctx.strokeStyle = '#333';
    ctx.lineCap = 'round';
    ctx.lineWidth = 3;
    ctx.beginPath();
    for (const w of h.walls) {
      ctx.moveTo(this.px(w[0] - ox), this.py(w[1] - oy));
      ctx.lineTo(this.px(w[2] - ox), this.py(w[3] - oy));
    }
    for (const s of h.surfaces) {
      ctx.moveTo(this.px(s[0] - ox), this.py(s[1] - oy));
      for (let i = 2; i + 1 < s.length; i += 2) ctx.lineTo(this.px(s[i] - ox), this.py(s[i + 1] - oy));
    }
    ctx.stroke();
    for (const b of h.boxes) {
      const x = this.px(b[0] - ox), y = this.py(b[3] - oy);
      const w = (b[2] - b[0]) * this.scale, hh = (b[3] - b[1]) * this.scale;
      ctx.fillStyle = '#d8d8d8';
      ctx.fillRect(x, y, w, hh);
      ctx.lineWidth = 2;
      ctx.strokeRect(x, y, w, hh);
    }

    // Bodies: the reference filled underneath, each engine a ring a little wider than the
    // last. Each disc or ring is drawn once into a sprite and copied (a gas of hundreds of
    // bodies is hundreds of copies a frame, not hundreds of anti-aliased paths).
    let ring = 0;
    let drawn = 0;
    h.sources.forEach((s, si) => {
      if (!this.shown[si]) { if (s.engine) ring++; return; }
      const pos = this.data[si].pos;
      const lineWidth = B > 50 ? 1.2 : 1.8;
      let count = 0;
      for (let b = 0; b < B; b++) {
        const i = (b * N + k) * 2;
        const x = pos[i], y = pos[i + 1];
        if (x !== x) continue;
        const r = Math.max(h.bodies[b][1] * this.scale, 2.5) + (s.engine ? 1.6 * ring : 0);
        const cx = this.px(x), cy = this.py(y);
        count++;
        if (r > 120) {   // a large body: drawn directly (few of them)
          ctx.beginPath();
          ctx.arc(cx, cy, r, 0, 2 * Math.PI);
          if (s.engine) { ctx.strokeStyle = s.colour; ctx.lineWidth = lineWidth; ctx.stroke(); }
          else { ctx.fillStyle = s.colour; ctx.globalAlpha = 0.75; ctx.fill(); ctx.globalAlpha = 1; }
          continue;
        }
        const sprite = this.sprite(s.colour, r, s.engine ? lineWidth : 0);
        ctx.drawImage(sprite, cx - sprite.half, cy - sprite.half, 2 * sprite.half, 2 * sprite.half);
      }
      if (s.engine) ring++;
      drawn = Math.max(drawn, count);
    });
    this.root.setAttribute('data-bodies-drawn', String(drawn));

    // Names, when there are few enough to read (at the reference's or first source's place).
    if (B <= 12 && this.data.length) {
      ctx.fillStyle = '#444';
      ctx.font = '11px sans-serif';
      const pos = this.data[0].pos;
      for (let b = 0; b < B; b++) {
        const i = (b * N + k) * 2;
        if (pos[i] !== pos[i]) continue;
        const r = Math.max(h.bodies[b][1] * this.scale, 2.5);
        ctx.fillText(h.bodies[b][0], this.px(pos[i]) + r + 5, this.py(pos[i + 1]) - r - 2);
      }
    }

    // Contacts that began in the last few frames: a ring that widens and fades. Only the
    // latest of each pair, and at most kMaxFlashes a source: a pair that touches
    // thousands of times in a blink (pi_billiard_1e8) is one ring, not thousands.
    const window_ = Math.max(3 * frameDt, h.duration / 150);
    const ages = 4, kMaxFlashes = 80;
    ctx.lineWidth = 2.5;
    h.sources.forEach((s, si) => {
      if (!this.shown[si]) return;
      const d = this.data[si];
      const end = countUpTo(d.ct, t);
      const first = countUpTo(d.ct, t - window_);
      if (first >= end) return;
      const byAge = [[], [], [], []];
      const seen = new Set();
      for (let c = end - 1; c >= first && seen.size < kMaxFlashes; c--) {
        const pair = d.ca[c] * 1e6 + d.cb[c];
        if (seen.has(pair)) continue;
        seen.add(pair);
        let x = 0, y = 0, n = 0, r = 0;
        for (const o of [d.ca[c], d.cb[c]]) {
          if (o >= B) continue;
          const i = (o * N + k) * 2;
          if (d.pos[i] !== d.pos[i]) continue;
          x += d.pos[i]; y += d.pos[i + 1]; n++;
          r = Math.max(r, h.bodies[o][1] * this.scale);
        }
        if (!n) continue;
        const a = Math.min(ages - 1, Math.floor((t - d.ct[c]) / window_ * ages));
        byAge[a].push([this.px(x / n), this.py(y / n), (n > 1 ? 0.5 * r : r) + 5 + 14 * (a + 0.5) / ages]);
      }
      ctx.strokeStyle = s.engine ? s.colour : '#666';
      for (let a = 0; a < ages; a++) {
        if (!byAge[a].length) continue;
        ctx.beginPath();
        for (const [cx, cy, radius] of byAge[a]) {
          ctx.moveTo(cx + radius, cy);
          ctx.arc(cx, cy, radius, 0, 2 * Math.PI);
        }
        ctx.globalAlpha = 1 - a / ages;
        ctx.stroke();
      }
      ctx.globalAlpha = 1;
    });

    ctx.fillStyle = '#222';
    ctx.font = '13px sans-serif';
    ctx.fillText(h.scenario + '   t = ' + t.toFixed(Math.max(0, Math.min(4, 2 - Math.floor(Math.log10(h.duration || 1))))) + ' s', 8, 16);

    this.slider.value = String(k);
    this.timeText.textContent = 't = ' + fmt(t, 4) + ' s of ' + fmt(h.duration, 4) + ' s';
    h.sources.forEach((s, si) => {
      const d = this.data[si], c = this.cells[si];
      const de = d.energy[k];
      c.de.textContent = fmt(de, 3);
      c.rel.textContent = d.e0 !== 0 ? fmt(Math.abs(de / d.e0), 3) : '\u2013';
      c.nc.textContent = String(countUpTo(d.ct, t));
    });
    this.framesDrawn++;
    this.root.setAttribute('data-frames-drawn', String(this.framesDrawn));
  }

  // A disc (lineWidth 0: the reference, translucent) or a ring, radius r CSS pixels.
  sprite(colour, r, lineWidth) {
    const key = colour + '|' + Math.round(r * 4) + '|' + lineWidth;
    this.sprites = this.sprites || new Map();
    let c = this.sprites.get(key);
    if (c) return c;
    const ratio = window.devicePixelRatio || 1;
    const half = Math.ceil(r + lineWidth + 1);
    c = document.createElement('canvas');
    c.width = c.height = Math.ceil(2 * half * ratio);
    c.half = half;
    const g = c.getContext('2d');
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.beginPath();
    g.arc(half, half, r, 0, 2 * Math.PI);
    if (lineWidth > 0) { g.strokeStyle = colour; g.lineWidth = lineWidth; g.stroke(); }
    else { g.globalAlpha = 0.75; g.fillStyle = colour; g.fill(); }
    this.sprites.set(key, c);
    return c;
  }

  // Pixels drawn (not background), and of those the barriers' near-black ones below the
  // title line (bodies are coloured or grey, names #444: neither counts as dark).
  ink() {
    const c = this.canvas, img = this.ctx.getImageData(0, 0, c.width, c.height).data;
    const titleRows = Math.ceil(24 * c.height / this.height);
    let n = 0, dark = 0;
    for (let i = 0; i < img.length; i += 4) {
      if (img[i] < 245 || img[i + 1] < 245 || img[i + 2] < 245) n++;
      if (img[i] <= 64 && img[i + 1] <= 64 && img[i + 2] <= 64 && i / 4 >= titleRows * c.width) dark++;
    }
    return [n, dark];
  }
}

async function start() {
  const roots = Array.from(document.querySelectorAll('div.player'));
  if (only) {
    for (const child of Array.from(document.body.children)) child.style.display = 'none';
    for (const r of roots) {
      if (r.getAttribute('data-scenario') !== only) continue;
      r.style.display = '';
      document.body.appendChild(r);
    }
  }
  const players = [];
  const failures = [];
  for (const root of roots) {
    if (only && root.getAttribute('data-scenario') !== only) continue;
    const p = new Player(root);
    try {
      await p.load();
      players.push(p);
    } catch (e) {
      failures.push(root.getAttribute('data-scenario') + ': ' + e.message);
      root.appendChild(el('p', { class: 'pl-error' }, 'The player could not start: ' + e.message));
      setTimeout(() => { throw e; });   // recorded by the page's error handler
    }
  }
  if (selftest) {
    for (const p of players) {
      for (let k = 0; k < p.h.frames; k++) p.draw(k, true);
      p.show(startAt !== null ? startAt : 0);
      p.draw(p.frame, true);
      const [ink, dark] = p.ink();
      p.root.setAttribute('data-ink', String(ink));
      p.root.setAttribute('data-barrier-ink', String(dark));
    }
  }
  if (autoplay) for (const p of players) p.play();
  document.documentElement.setAttribute('data-players', String(players.length));
  document.documentElement.setAttribute('data-player-status', failures.length ? 'failed' : 'ok');
}

if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', start);
else start();
})();
</script>
)JS";
}

}  // namespace physval::report_detail
