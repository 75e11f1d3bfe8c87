// Read times of large designs in the page's wasm (issue targets: an OBJ of 1M triangles within
// 2x the native 1 s, a GLB within 2x the native 0.3 s). A dome of 1 002 528 triangles, made in
// the page as an OBJ (text) and as an indexed GLB (f32 positions, u32 indices, as exporters
// write it), opened with `Session.fromFile` as panels; the time is the design's `readSeconds`
// (parse and weld, measured inside wasm), three runs each.
// `DUPIN_URL=... node bench-read.mjs`
import { openPage } from './harness.mjs';

const { browser, page } = await openPage({ webgpu: false });
try {
  const r = await page.evaluate(async () => {
    const { Session } = (await import('./wasm.js')).wasm; // the build the page loaded
    // 709 x 709 vertices: 2 x 708 x 708 = 1 002 528 triangles.
    const n = 709;
    const positions = new Float32Array(n * n * 3);
    for (let i = 0; i < n; i++) {
      for (let j = 0; j < n; j++) {
        const [x, y] = [(i / (n - 1)) * 40 - 20, (j / (n - 1)) * 40 - 20];
        positions.set([x, y, 8 - (x * x + y * y) / 100], 3 * (i * n + j));
      }
    }
    const indices = new Uint32Array(2 * (n - 1) * (n - 1) * 3);
    let k = 0;
    for (let i = 0; i + 1 < n; i++) {
      for (let j = 0; j + 1 < n; j++) {
        const a = i * n + j, b = a + n;
        indices.set([a, b, b + 1, a, b + 1, a + 1], k);
        k += 6;
      }
    }
    const lines = [];
    for (let v = 0; v < n * n; v++) lines.push(`v ${positions[3 * v]} ${positions[3 * v + 1]} ${positions[3 * v + 2]}`);
    for (let t = 0; t < indices.length; t += 3) lines.push(`f ${indices[t] + 1} ${indices[t + 1] + 1} ${indices[t + 2] + 1}`);
    const obj = new TextEncoder().encode(lines.join('\n') + '\n');
    // GLB: one buffer (indices, then positions), one mesh, one node.
    const bin = new Uint8Array(indices.byteLength + positions.byteLength);
    bin.set(new Uint8Array(indices.buffer), 0);
    bin.set(new Uint8Array(positions.buffer), indices.byteLength);
    const min = [-20, -20, 0], max = [20, 20, 8];
    const gltf = {
      asset: { version: '2.0' },
      scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
      meshes: [{ primitives: [{ attributes: { POSITION: 1 }, indices: 0 }] }],
      buffers: [{ byteLength: bin.byteLength }],
      bufferViews: [
        { buffer: 0, byteOffset: 0, byteLength: indices.byteLength, target: 34963 },
        { buffer: 0, byteOffset: indices.byteLength, byteLength: positions.byteLength, target: 34962 },
      ],
      accessors: [
        { bufferView: 0, componentType: 5125, count: indices.length, type: 'SCALAR' },
        { bufferView: 1, componentType: 5126, count: n * n, type: 'VEC3', min, max },
      ],
    };
    let json = new TextEncoder().encode(JSON.stringify(gltf));
    const pad = (4 - (json.length % 4)) % 4;
    json = new Uint8Array([...json, ...new Array(pad).fill(0x20)]);
    const glb = new Uint8Array(12 + 8 + json.length + 8 + bin.length);
    const dv = new DataView(glb.buffer);
    dv.setUint32(0, 0x46546c67, true); dv.setUint32(4, 2, true); dv.setUint32(8, glb.length, true);
    dv.setUint32(12, json.length, true); dv.setUint32(16, 0x4e4f534a, true); glb.set(json, 20);
    const o = 20 + json.length;
    dv.setUint32(o, bin.length, true); dv.setUint32(o + 4, 0x004e4942, true); glb.set(bin, o + 8);
    const out = { triangles: indices.length / 3, objMB: obj.length / 1e6, glbMB: glb.length / 1e6, obj: [], glb: [] };
    for (let run = 0; run < 3; run++) {
      for (const [name, bytes] of [['dome.obj', obj], ['dome.glb', glb]]) {
        const s = Session.fromFile(name, bytes, { importAs: 'panels' });
        const d = s.metrics().design;
        out[name.slice(5)].push(d.readSeconds);
        s.free();
      }
    }
    return out;
  });
  const range = (xs) => `${(Math.min(...xs) * 1000).toFixed(0)}-${(Math.max(...xs) * 1000).toFixed(0)} ms`;
  console.log(`${r.triangles} triangles in the page's wasm: OBJ (${r.objMB.toFixed(0)} MB) read in ${range(r.obj)}, GLB (${r.glbMB.toFixed(0)} MB) in ${range(r.glb)}`);
} finally {
  await browser.close();
}
