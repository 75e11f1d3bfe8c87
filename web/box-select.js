// Box selection of panel-mesh vertices in edit mode: a Shift-drag on the 3D view draws a
// rectangle; on release the worker finds the vertices projected inside it
// (Session.verticesInRect, with the viewer's matrix), and the page marks them; dragging one of
// them then moves the whole group (Session.dragVertices). This module keeps the rectangle, the
// selection and its markers; main.js decides when a press selects and when it drags.
//
// The markers are drawn on a 2D canvas over the 3D view from the selected vertices' positions,
// projected with Viewer.project: the held vertices of a group drag move by the drag's
// translation exactly, so the page knows where they are without asking the worker.
import { fitOverlay } from './overlay.js';

/** Smallest rectangle side, in CSS pixels, that selects (a shorter Shift-drag is a slip). */
const MIN_SIDE = 3;

export class BoxSelection {
  /** `canvas`: the 3D view; `hint`: the element that says what is selected. */
  constructor(canvas, hint) {
    this.canvas = canvas;
    this.hint = hint;
    this.band = document.createElement('div');
    this.band.className = 'select-band';
    this.band.dataset.testid = 'select-band';
    this.band.hidden = true;
    this.overlay = document.createElement('canvas');
    this.overlay.className = 'select-overlay';
    this.overlay.dataset.testid = 'selection-overlay';
    this.overlay.setAttribute('aria-hidden', 'true');
    canvas.after(this.band, this.overlay);
    this.box = null; // { x0, y0, x1, y1 } in canvas CSS pixels while a rectangle is drawn
    this.vertices = []; // selected vertex numbers, increasing
    this.points = []; // their positions, 3 numbers each
    this.offset = [0, 0, 0]; // the running group drag's translation
  }

  get size() { return this.vertices.length; }

  has(vertex) { return this.vertices.includes(vertex); }

  /** Starts a rectangle at canvas point (x, y). */
  begin(x, y) {
    this.box = { x0: x, y0: y, x1: x, y1: y };
    this.placeBand();
  }

  get active() { return this.box !== null; }

  move(x, y) {
    if (!this.box) return;
    this.box.x1 = x;
    this.box.y1 = y;
    this.placeBand();
  }

  /** Ends the rectangle: its corners in normalised device coordinates `[x0, y0, x1, y1]`, or
   * null for a rectangle too small to mean anything. */
  end() {
    const b = this.box;
    this.box = null;
    this.band.hidden = true;
    if (!b || Math.abs(b.x1 - b.x0) < MIN_SIDE || Math.abs(b.y1 - b.y0) < MIN_SIDE) return null;
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    const nx = (x) => (x / w) * 2 - 1, ny = (y) => 1 - (y / h) * 2;
    return [nx(b.x0), ny(b.y0), nx(b.x1), ny(b.y1)];
  }

  placeBand() {
    const b = this.box;
    const s = this.band.style;
    s.left = `${this.canvas.offsetLeft + Math.min(b.x0, b.x1)}px`;
    s.top = `${this.canvas.offsetTop + Math.min(b.y0, b.y1)}px`;
    s.width = `${Math.abs(b.x1 - b.x0)}px`;
    s.height = `${Math.abs(b.y1 - b.y0)}px`;
    this.band.hidden = false;
  }

  /** The worker's answer: `{ vertices, points }`. */
  set({ vertices, points }) {
    this.vertices = Array.from(vertices);
    this.points = Array.from(points);
    this.offset = [0, 0, 0];
    this.describe();
  }

  clear() {
    if (!this.vertices.length && !this.box) return;
    this.vertices = [];
    this.points = [];
    this.offset = [0, 0, 0];
    this.box = null;
    this.band.hidden = true;
    this.describe();
  }

  /** The selection without `lead` (the vertices a drag of `lead` takes along). */
  groupOf(lead) { return this.vertices.filter((v) => v !== lead); }

  /** A group drag's translation so far (markers follow it). */
  follow(delta) { this.offset = delta; }

  /** A group drag ended at translation `delta`: the selection is where it was put. */
  commit(delta) {
    this.points = this.points.map((c, i) => c + delta[i % 3]);
    this.offset = [0, 0, 0];
  }

  describe() {
    const n = this.vertices.length;
    this.hint.hidden = n === 0;
    this.hint.dataset.count = String(n);
    this.hint.textContent = n === 0 ? ''
      : `${n} ${n === 1 ? 'vertex' : 'vertices'} selected: drag one of them to move them together (Esc clears)`;
  }

  /** Redraws the markers with `project` (Viewer.project: NDC of a 3D point, or undefined). */
  draw(project) {
    const o = this.overlay;
    const { g, w, h, dpr } = fitOverlay(o, this.canvas);
    o.hidden = this.vertices.length === 0;
    if (o.hidden) return;
    const s = 3 * dpr;
    g.fillStyle = '#f2c14e';
    g.strokeStyle = '#0b0c10';
    g.lineWidth = dpr;
    const [dx, dy, dz] = this.offset;
    for (let i = 0; i < this.points.length; i += 3) {
      const p = project(this.points[i] + dx, this.points[i + 1] + dy, this.points[i + 2] + dz);
      if (!p) continue;
      const x = (p[0] + 1) * 0.5 * w, y = (1 - p[1]) * 0.5 * h;
      g.fillRect(x - s, y - s, 2 * s, 2 * s);
      g.strokeRect(x - s, y - s, 2 * s, 2 * s);
    }
  }
}
