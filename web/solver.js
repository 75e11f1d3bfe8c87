// The page's side of web/worker.js: starts the worker and turns its messages into callbacks.
// Every load gets a new generation number; replies for older loads are ignored.
//
// A wasm trap or out-of-memory leaves the worker's module unusable, and a step may run longer
// than anyone wants to wait: `restart()` terminates the worker (whatever it is computing) and
// starts a fresh one, and the page reloads its last good state into it.
export class Solver {
  /** `url`: the worker script's (wasm.js's `workerUrl`: it names the module build to load). */
  constructor(url, { onState, onError, onExport, onPick, onFault, onSelection }) {
    this.url = url;
    this.gen = 0;
    this.callbacks = { onState, onError, onExport, onPick, onFault, onSelection };
    this.start();
  }

  start() {
    const { onState, onError, onExport, onPick, onFault, onSelection } = this.callbacks;
    const worker = new Worker(this.url, { type: 'module' });
    this.worker = worker;
    this.ready = new Promise((resolve, reject) => {
      worker.addEventListener('error', (e) => reject(new Error(`solver worker: ${e.message ?? 'failed to start'}`)), { once: true });
      worker.addEventListener('message', (e) => { if (e.data.type === 'ready') resolve(); });
    });
    // An error that escaped the worker's handlers: the worker is in an unknown state.
    worker.addEventListener('error', (e) => {
      if (this.worker === worker) onFault?.(e.message ?? 'the solver worker failed');
    });
    worker.addEventListener('message', (e) => {
      if (this.worker !== worker) return;
      const m = e.data;
      if (m.type === 'error' && m.fatal) { onFault?.(m.message); return; }
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
      else if (m.type === 'selection') onSelection?.(m);
    });
  }

  /** Terminates the worker, cancelling whatever it computes, and starts a fresh one; resolves
   * once the new worker is ready. */
  restart() {
    this.gen += 1;
    this.worker.terminate();
    this.start();
    return this.ready;
  }

  /** Starts `config` (a Session config) and replays `steps` steps; `field` names the input
   * that caused the load (bad configurations report back to it); `layers` are the offset and
   * support layers to draw where the run has them; `file` ({ name, bytes }) opens a design
   * with `config` as its import options (Session.fromFile); `edits` (`{ v, group, path }`
   * each: the dragged vertex, the vertices dragged along and the drag's waypoints, its end
   * last) are vertex drags replayed after the steps (Session.dragVertices, each waypoint
   * committed), each run to its end. */
  load(config, { steps = 1, mode, field = null, layers = null, file = null, edits = [] } = {}) {
    this.gen += 1;
    this.worker.postMessage({ type: 'load', gen: this.gen, config, steps, mode, field, layers, file, edits });
    return this.gen;
  }

  post(type, extra = {}) { this.worker.postMessage({ type, gen: this.gen, ...extra }); }
}
