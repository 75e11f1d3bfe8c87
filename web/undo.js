// Undo and redo of every setting. The whole configuration lives in the URL hash (config.js), so
// a setting is the hash without its step count and camera (orbiting and stepping are not edits);
// an entry keeps the latest full hash of its setting, so undo returns to the run as it was left,
// replayed to the same step (runs are deterministic, so the same mesh, bit for bit).

/** The part of hash `h` that counts as a setting. */
export function settingKey(h) {
  const p = new URLSearchParams(h.replace(/^#/, ''));
  p.delete('steps');
  p.delete('cam');
  return p.toString();
}

/** Past and future settings around the current one, at most `limit` each way. */
export class SettingsHistory {
  constructor(limit = 200) {
    this.limit = limit;
    this.past = [];
    this.future = [];
    this.current = null; // { hash, key }
  }

  /** Records hash `h` the page now shows: a new setting pushes the previous one (and drops the
   * redo list, as any editor does); the same setting only updates its hash. */
  note(h) {
    const key = settingKey(h);
    if (this.current?.key === key) {
      this.current.hash = h;
      return;
    }
    if (this.current) {
      this.past.push(this.current);
      if (this.past.length > this.limit) this.past.shift();
    }
    this.future = [];
    this.current = { hash: h, key };
  }

  /** The hash to restore for undo, or null when there is nothing to undo. */
  undo() {
    if (!this.past.length) return null;
    this.future.push(this.current);
    this.current = this.past.pop();
    return this.current.hash;
  }

  /** The hash to restore for redo, or null. */
  redo() {
    if (!this.future.length) return null;
    this.past.push(this.current);
    this.current = this.future.pop();
    return this.current.hash;
  }
}
