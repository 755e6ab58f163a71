"use strict";
// The motion player of report.html: per scenario, one canvas per run, the same frame and
// camera in all. The frames are the report's animation data (docs/report-schema.md,
// Animation), inflated by the browser's own DecompressionStream; charts.py writes the
// page's data (HB_PLAYER_DATA) and inlines this file, so the page needs no network.
(function () {
  const YAW = (30 * Math.PI) / 180, PITCH = (15 * Math.PI) / 180;
  const CY = Math.cos(YAW), SY = Math.sin(YAW), CP = Math.cos(PITCH), SP = Math.sin(PITCH);
  const SIZE = 210;  // panel, CSS pixels
  const state = { ready: false, error: null, players: [], drawMs: [] };
  window.hbPlayer = state;

  function bytesOf(b64) {
    const bin = atob(b64);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
    return out;
  }

  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // The varints back to coordinates (integers, unit_metres each), frame after frame, with
  // the encoder's prediction: in frame 0 the previous vertex of the strand (0 at the root),
  // after that the same coordinate one frame back plus the move of the previous vertex.
  function undo(bytes, sizes) {
    const root = [];
    for (const n of sizes) for (let v = 0; v < n; ++v) root.push(v === 0, v === 0, v === 0);
    const per = root.length;
    let count = 0;
    for (const b of bytes) if (!(b & 0x80)) ++count;
    if (count % per) throw new Error("animation data: not a whole number of frames");
    const q = new Int32Array(count);
    let z = 0, mul = 1, at = 0;
    for (const b of bytes) {
      z += (b & 0x7f) * mul;
      mul *= 128;
      if (b & 0x80) continue;
      const r = z % 2 ? -(z + 1) / 2 : z / 2;
      const i = at % per, f = at - i;
      let p;
      if (f === 0) p = root[i] ? 0 : q[at - 3];
      else p = root[i] ? q[at - per] : q[at - per] + q[at - 3] - q[at - per - 3];
      q[at++] = r + p;
      z = 0;
      mul = 1;
    }
    return q;
  }

  async function decode(b64, sizes) {
    return undo(await inflate(bytesOf(b64)), sizes);
  }

  // World position of coordinate triple j of recorded frame k: head(k) applied to the
  // head-frame position.
  function world(sc, q, k, j, out) {
    const per = sc.perFrame, h = sc.head[k], u = sc.unit;
    const x = q[k * per + j] * u, y = q[k * per + j + 1] * u, z = q[k * per + j + 2] * u;
    out[0] = h[3] * x + h[4] * y + h[5] * z + h[0];
    out[1] = h[6] * x + h[7] * y + h[8] * z + h[1];
    out[2] = h[9] * x + h[10] * y + h[11] * z + h[2];
    return out;
  }

  // The stills' camera (charts.py camera()): orthographic, 30 degrees to the right and 15
  // above, centred on `c`; screen y up.
  function project(c, p, out) {
    const x = p[0] - c[0], y = p[1] - c[1], z = p[2] - c[2];
    const x1 = CY * x + SY * z, z1 = -SY * x + CY * z;
    out[0] = x1;
    out[1] = CP * y - SP * z1;
    return out;
  }

  function colour(lut, d) {
    const t = (Math.log10(Math.min(Math.max(d, 1e-4), 1)) + 4) / 4;
    return lut[Math.min(lut.length - 1, Math.floor(t * lut.length))];
  }

  class Player {
    constructor(root, sc) {
      this.sc = sc;
      this.k = 0;
      this.speed = 1;
      this.playing = false;
      this.panels = [];
      const strip = root.querySelector(".hb-panels");
      for (const p of sc.panels) {
        const fig = document.createElement("figure");
        fig.className = "hb-panel" + (p.status === "ok" ? "" : " hb-" + p.status);
        const cap = document.createElement("figcaption");
        cap.innerHTML = "<b></b><br><span></span>";
        cap.firstChild.textContent = p.label;
        cap.lastChild.textContent = p.verdict;
        const canvas = document.createElement("canvas");
        canvas.width = canvas.height = SIZE;
        fig.append(cap, canvas);
        strip.append(fig);
        this.panels.push({ run: p, canvas, ctx: canvas.getContext("2d") });
      }
      this.slider = root.querySelector(".hb-slider");
      this.slider.max = String(sc.frames.length - 1);
      this.label = root.querySelector(".hb-frame");
      this.button = root.querySelector(".hb-play");
      this.timeline = root.querySelector(".hb-timeline");
      this.slider.addEventListener("input", () => this.set(Number(this.slider.value)));
      this.button.addEventListener("click", () => (this.playing ? this.pause() : this.play()));
      root.querySelector(".hb-speed").addEventListener("change", (e) => (this.speed = Number(e.target.value)));
    }

    // Every run's frames, then the view: the head's mean position in the middle, and the
    // reference's strands and the head everywhere in sight, at most 3 mean strand lengths
    // beyond the head (a blown-up run must not shrink the others).
    async load(lut) {
      const sc = this.sc;
      this.lut = lut;
      const ref = await decode(sc.reference.data, sc.sizes);
      for (const p of this.panels) p.q = p.run.data === null ? ref : await decode(p.run.data, sc.sizes);
      this.ref = ref;
      const c = [0, 0, 0];
      for (const h of sc.head) for (let a = 0; a < 3; ++a) c[a] += h[a] / sc.head.length;
      this.centre = c;
      const w = [0, 0, 0], s = [0, 0];
      let extent = 0;
      for (let k = 0; k < sc.head.length; ++k) {
        project(c, [sc.head[k][0], sc.head[k][1], sc.head[k][2]], s);
        extent = Math.max(extent, Math.abs(s[0]) + sc.headRadius, Math.abs(s[1]) + sc.headRadius);
        if (k >= sc.reference.frames) continue;
        for (let j = 0; j < sc.perFrame; j += 3) {
          project(c, world(sc, ref, k, j, w), s);
          extent = Math.max(extent, Math.abs(s[0]), Math.abs(s[1]));
        }
      }
      extent = Math.min(extent, sc.headRadius + 3 * sc.meanStrandLength + this.headTravel());
      this.scale = (0.5 * SIZE) / (1.05 * extent);
      this.drawTimeline();
      this.set(0);
    }

    headTravel() {
      const s = [0, 0];
      let far = 0;
      for (const h of this.sc.head) far = Math.max(far, Math.hypot(...project(this.centre, h.slice(0, 3), s)));
      return far;
    }

    // Canvas pixel of a world position (what the browser test checks against the report).
    pixel(p) {
      const s = project(this.centre, p, [0, 0]);
      return [0.5 * SIZE + s[0] * this.scale, 0.5 * SIZE - s[1] * this.scale];
    }

    set(k) {
      this.k = k;
      this.slider.value = String(k);
      const f = this.sc.frames[k];
      this.label.textContent = `frame ${f} of ${this.sc.frameCount}, t = ${((f + 1) * this.sc.dt).toFixed(2)} s`;
      const t0 = performance.now();
      for (const p of this.panels) this.drawPanel(p, k);
      this.drawCursor();
      state.drawMs.push(performance.now() - t0);
    }

    drawPanel(panel, k) {
      const sc = this.sc, g = panel.ctx, run = panel.run;
      g.clearRect(0, 0, SIZE, SIZE);
      // A run that stopped is shown at its last frame, faded.
      const kk = Math.min(k, run.frames - 1);
      const h = sc.head[k];
      const hc = this.pixel([h[0], h[1], h[2]]);
      g.fillStyle = "#d9d9d9";
      g.beginPath();
      g.arc(hc[0], hc[1], sc.headRadius * this.scale, 0, 2 * Math.PI);
      g.fill();
      // A mark on the head's +z, so its turning shows.
      const front = this.pixel([h[0] + h[5] * sc.headRadius, h[1] + h[8] * sc.headRadius, h[2] + h[11] * sc.headRadius]);
      g.fillStyle = "#8c8c8c";
      g.beginPath();
      g.arc(front[0], front[1], 3, 0, 2 * Math.PI);
      g.fill();
      if (kk < 0) {
        this.note(g, "no frames recorded");
        return;
      }
      g.globalAlpha = kk < k ? 0.35 : 1;
      const a = [0, 0, 0], b = [0, 0, 0], ra = [0, 0, 0], rb = [0, 0, 0];
      const refOk = kk < sc.reference.frames;
      let j = 0;
      for (let s = 0; s < sc.sizes.length; ++s) {
        g.lineWidth = sc.named[s] ? 2.2 : 1;
        let da = 0;
        world(sc, panel.q, kk, j, a);
        if (refOk) da = Math.hypot(a[0] - world(sc, this.ref, kk, j, ra)[0], a[1] - ra[1], a[2] - ra[2]) / sc.meanStrandLength;
        let pa = this.pixel(a);
        for (let v = 1; v < sc.sizes[s]; ++v) {
          world(sc, panel.q, kk, j + 3 * v, b);
          let db = 0;
          if (refOk) db = Math.hypot(b[0] - world(sc, this.ref, kk, j + 3 * v, rb)[0], b[1] - rb[1], b[2] - rb[2]) / sc.meanStrandLength;
          const pb = this.pixel(b);
          g.strokeStyle = refOk ? colour(this.lut, 0.5 * (da + db)) : "#999999";
          g.beginPath();
          g.moveTo(pa[0], pa[1]);
          g.lineTo(pb[0], pb[1]);
          g.stroke();
          pa = pb;
          da = db;
        }
        j += 3 * sc.sizes[s];
      }
      g.globalAlpha = 1;
      if (kk < k) this.note(g, `stopped at frame ${sc.frames[kk]}`);
    }

    note(g, text) {
      g.fillStyle = "#c0392b";
      g.font = "12px sans-serif";
      g.textAlign = "center";
      g.fillText(text, 0.5 * SIZE, SIZE - 8);
    }

    // The script's phases shaded along the slider, each run's verdict frame ticked red.
    drawTimeline() {
      const sc = this.sc, c = this.timeline, g = c.getContext("2d");
      const w = c.width, total = sc.frameCount * sc.dt;
      g.clearRect(0, 0, w, c.height);
      for (const p of sc.phases) {
        g.fillStyle = p.colour;
        g.globalAlpha = 0.35;
        g.fillRect((p.start / total) * w, 0, ((p.end - p.start) / total) * w, c.height);
      }
      g.globalAlpha = 1;
      g.fillStyle = "#c0392b";
      for (const p of sc.panels)
        if (p.began !== null) g.fillRect(((p.began + 1) / sc.frameCount) * w - 1, 0, 2, c.height);
      this.timelineImage = g.getImageData(0, 0, w, c.height);
    }

    drawCursor() {
      const c = this.timeline, g = c.getContext("2d");
      if (!this.timelineImage) return;
      g.putImageData(this.timelineImage, 0, 0);
      const x = ((this.sc.frames[this.k] + 1) / this.sc.frameCount) * c.width;
      g.fillStyle = "#000";
      g.fillRect(x - 1, 0, 2, c.height);
    }

    play() {
      this.playing = true;
      this.button.textContent = "pause";
      let last = null, acc = 0;
      const step = this.sc.stride * this.sc.dt;
      const tick = (ts) => {
        if (!this.playing) return;
        if (last !== null) acc += ((ts - last) / 1000) * this.speed;
        last = ts;
        let k = this.k;
        while (acc >= step) {
          acc -= step;
          k = (k + 1) % this.sc.frames.length;
        }
        if (k !== this.k) this.set(k);
        requestAnimationFrame(tick);
      };
      requestAnimationFrame(tick);
    }

    pause() {
      this.playing = false;
      this.button.textContent = "play";
    }
  }

  async function start() {
    const data = JSON.parse(document.getElementById("hb-player-data").textContent);
    for (const sc of data.scenarios) {
      sc.perFrame = 3 * sc.sizes.reduce((x, y) => x + y, 0);
      const root = document.getElementById(sc.id);
      const p = new Player(root, sc);
      state.players.push(p);
      await p.load(data.viridis);
    }
    state.ready = true;
  }

  start().catch((e) => {
    state.error = String(e);
    console.error("hairbench player: " + e);
  });
})();
