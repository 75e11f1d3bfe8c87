// The page's side of web/worker.js: starts the worker and turns its messages into callbacks.
// Every load gets a new generation number; replies for older loads are ignored.
export class Solver {
  constructor({ onState, onError, onExport, onPick }) {
    this.gen = 0;
    this.worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
    this.ready = new Promise((resolve, reject) => {
      this.worker.addEventListener('error', (e) => reject(new Error(`solver worker: ${e.message ?? 'failed to start'}`)), { once: true });
      this.worker.addEventListener('message', (e) => { if (e.data.type === 'ready') resolve(); });
    });
    this.worker.addEventListener('message', (e) => {
      const m = e.data;
      if (m.type === 'error' && m.load) { // a rejected load keeps the old run going
        if (m.gen === this.gen) this.gen = m.active;
        onError(m);
        return;
      }
      if (m.gen !== this.gen) return;
      if (m.type === 'state') onState(m);
      else if (m.type === 'error') onError(m);
      else if (m.type === 'export') onExport(m);
      else if (m.type === 'pick') onPick?.(m);
    });
  }

  /** Starts `config` (a Session config) and replays `steps` steps; `field` names the input
   * that caused the load (bad configurations report back to it); `layers` are the offset and
   * support layers to draw where the run has them. */
  load(config, { steps = 1, mode, field = null, layers = null } = {}) {
    this.gen += 1;
    this.worker.postMessage({ type: 'load', gen: this.gen, config, steps, mode, field, layers });
    return this.gen;
  }

  post(type, extra = {}) { this.worker.postMessage({ type, gen: this.gen, ...extra }); }
}
