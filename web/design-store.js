// The last opened design, kept in the browser (IndexedDB) so that a reload or a copied link
// on the same machine shows it again. It never leaves the machine. Storage may be unavailable
// (private windows, a blocked origin): then nothing is kept and the page says the file is not
// here, as before.
const DB = 'dupin';
const STORE = 'designs';
const KEY = 'last';

function open() {
  return new Promise((resolve, reject) => {
    const req = indexedDB.open(DB, 1);
    req.onupgradeneeded = () => req.result.createObjectStore(STORE);
    req.onsuccess = () => resolve(req.result);
    req.onerror = () => reject(req.error);
  });
}

async function transact(mode, work) {
  const db = await open();
  try {
    return await new Promise((resolve, reject) => {
      const tx = db.transaction(STORE, mode);
      const req = work(tx.objectStore(STORE));
      tx.oncomplete = () => resolve(req?.result);
      tx.onerror = () => reject(tx.error);
      tx.onabort = () => reject(tx.error);
    });
  } finally {
    db.close();
  }
}

/** Keeps `design` ({ name, bytes, unit, note }); false when the browser would not. */
export async function saveDesign(design) {
  try {
    await transact('readwrite', (s) => s.put({ ...design, saved: Date.now() }, KEY));
    return true;
  } catch {
    return false;
  }
}

/** The kept design, or null. */
export async function loadDesign() {
  try {
    const d = await transact('readonly', (s) => s.get(KEY));
    return d && typeof d.name === 'string' && d.bytes instanceof Uint8Array ? d : null;
  } catch {
    return null;
  }
}
