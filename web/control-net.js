// The control net of an opened NURBS surface, drawn over the 3D view in edit mode and picked
// there: main.js drags a picked control point in the plane through it facing the view, and the
// worker reshapes the surface (Session.moveControlPoint) and the panelling follows it.
//
// The net is a few dozen to a few thousand points, so it is drawn on a 2D canvas from
// Viewer.project and picked in screen space here; the surface and its panels stay in wasm.
import { fitOverlay } from './overlay.js';

/** How near (CSS pixels) a press must be to a control point to pick it. */
const PICK_PX = 12;

export class ControlNetOverlay {
  /** `canvas`: the 3D view. */
  constructor(canvas) {
    this.canvas = canvas;
    this.overlay = document.createElement('canvas');
    this.overlay.className = 'net-overlay';
    this.overlay.dataset.testid = 'control-net';
    this.overlay.setAttribute('aria-hidden', 'true');
    this.overlay.hidden = true;
    canvas.after(this.overlay);
    this.net = null; // { nu, nv, points } (design.controlNet, less the view origin)
    this.origin = [0, 0, 0];
    this.shown = false;
    this.active = -1; // the point being dragged
  }

  /**
   * The run's control net (`design.controlNet`, in the design's coordinates), or null, drawn
   * and dragged relative to the view's `origin` (the metrics' `viewOrigin`) as the panels are.
   */
  set(net, origin) {
    this.origin = origin ? Array.from(origin) : [0, 0, 0];
    this.net = net
      ? { nu: net.nu, nv: net.nv, points: Array.from(net.points, (c, i) => c - this.origin[i % 3]) }
      : null;
    this.overlay.dataset.points = String(this.net ? this.net.nu * this.net.nv : 0);
  }

  get available() { return this.net !== null; }

  show(on) { this.shown = on && this.net !== null; }

  /** Control point `index` drawn at `p` (while it is dragged). */
  place(index, p) {
    if (!this.net) return;
    for (let k = 0; k < 3; k++) this.net.points[3 * index + k] = p[k];
  }

  /** Control point `index` in the view's coordinates. */
  point(index) { return this.net.points.slice(3 * index, 3 * index + 3); }

  /** A point of the view in the design's coordinates (what Session.moveControlPoint takes). */
  toDesign(p) { return p.map((c, k) => c + this.origin[k]); }

  /** The control point nearest canvas point (x, y) within PICK_PX, or -1. */
  pick(x, y, project) {
    if (!this.net) return -1;
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    let best = -1, bestD = PICK_PX;
    const n = this.net.nu * this.net.nv;
    for (let i = 0; i < n; i++) {
      const q = project(...this.point(i));
      if (!q) continue;
      const d = Math.hypot((q[0] + 1) * 0.5 * w - x, (1 - q[1]) * 0.5 * h - y);
      if (d < bestD) { bestD = d; best = i; }
    }
    return best;
  }

  /** Redraws the net (its rows and columns, then its points) with `project` (Viewer.project). */
  draw(project) {
    const o = this.overlay;
    o.hidden = !this.shown;
    if (!this.shown) return;
    const { g, w, h, dpr } = fitOverlay(o, this.canvas);
    const { nu, nv } = this.net;
    const screen = [];
    for (let i = 0; i < nu * nv; i++) {
      const q = project(...this.point(i));
      screen.push(q ? [(q[0] + 1) * 0.5 * w, (1 - q[1]) * 0.5 * h] : null);
    }
    g.strokeStyle = 'rgba(242, 193, 78, 0.8)';
    g.lineWidth = dpr;
    const segment = (a, b) => {
      if (!screen[a] || !screen[b]) return;
      g.moveTo(...screen[a]);
      g.lineTo(...screen[b]);
    };
    g.beginPath();
    for (let i = 0; i < nu; i++) for (let j = 0; j < nv; j++) {
      if (j + 1 < nv) segment(i * nv + j, i * nv + j + 1);
      if (i + 1 < nu) segment(i * nv + j, (i + 1) * nv + j);
    }
    g.stroke();
    const s = 4 * dpr;
    screen.forEach((p, i) => {
      if (!p) return;
      g.fillStyle = i === this.active ? '#ffffff' : '#f2c14e';
      g.beginPath();
      g.arc(p[0], p[1], i === this.active ? s * 1.3 : s, 0, 2 * Math.PI);
      g.fill();
      g.strokeStyle = '#0b0c10';
      g.stroke();
    });
  }
}
