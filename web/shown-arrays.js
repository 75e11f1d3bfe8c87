// The worker's mesh arrays as the page holds them. A state whose mesh only grew (a P-Hex run
// revealing its triangulation a layer at a time) carries only what it added
// (`Session.meshSince`), so revealing costs the worker the new layer, not every triangle shown;
// here it is appended to what the page holds. Each array keeps spare room (doubling), so a
// reveal of n layers copies each value O(1) times; the arrays handed out are views of the held
// part, which later appends never write.

const FIELDS = ['positions', 'normals', 'indices', 'colors', 'edges', 'panelPositions', 'panelFaces'];

function sameKey(a, b) {
  return !!a && !!b && a.revision === b.revision && a.faces === b.faces && a.vertices === b.vertices;
}

export class ShownArrays {
  constructor() {
    this.key = null; // the key of the mesh held (undefined key: nothing can be added to it)
    this.held = null; // per field: { data (typed array with room), length }
    this.appended = 0; // states appended since the last whole mesh
  }

  /** The whole mesh after the worker's `mesh` (a state's): `mesh` itself when whole, else the
   * held arrays with `mesh` appended. `null` when `mesh` adds to a mesh the page does not hold
   * (a state was missed): the worker must send a whole one (its `resync`). */
  apply(mesh) {
    if (!mesh.appendTo) {
      this.key = mesh.key ?? null;
      this.held = Object.fromEntries(FIELDS.map((f) => [f, { data: mesh[f], length: mesh[f].length }]));
      this.appended = 0;
      return mesh;
    }
    if (!this.held || !sameKey(mesh.appendTo, this.key)) {
      this.key = null;
      this.held = null;
      return null;
    }
    for (const f of FIELDS) {
      const h = this.held[f];
      const add = mesh[f];
      const length = h.length + add.length;
      if (length > h.data.length) {
        const grown = new h.data.constructor(Math.max(length, 2 * h.data.length));
        grown.set(h.data.subarray(0, h.length));
        h.data = grown;
      }
      h.data.set(add, h.length);
      h.length = length;
    }
    this.key = mesh.key ?? null;
    this.appended += 1;
    const whole = { viewOrigin: mesh.viewOrigin, key: mesh.key };
    for (const f of FIELDS) whole[f] = this.held[f].data.subarray(0, this.held[f].length);
    return whole;
  }

  /** The held arrays (views), for tests. */
  arrays() {
    return this.held && Object.fromEntries(FIELDS.map((f) => [f, this.held[f].data.subarray(0, this.held[f].length)]));
  }
}
