// Quad grids as OBJ for the planarisation figures of BENCHMARKS.md (`dupin planarize --input`):
//   node tests/bench/grid-obj.mjs noisy N > gridN.obj   N x N quads of edge 0.05 on the saddle
//     z = 0.3 ((x - 2.5)² - (y - 2.5)²) / 20 with seeded height noise of 8% of an edge (a design
//     near planar; the grid of tests/workloads_wasm.rs at N = 100);
//   node tests/bench/grid-obj.mjs skew N > skewN.obj   `skew_quad_grid(N, 30)`: [-1, 1]² turned
//     30 degrees on z = xy (every quad far from planar).
const [kind, nArg] = process.argv.slice(2);
const n = Number(nArg);
if (!['noisy', 'skew'].includes(kind) || !(n >= 1)) {
  console.error('usage: node grid-obj.mjs noisy|skew N');
  process.exit(2);
}
let seed = 10000n;
const M = (1n << 64n) - 1n;
const rnd = () => {
  seed = (seed * 6364136223846793005n + 1442695040888963407n) & M;
  return Number(seed >> 11n) / 2 ** 53;
};
const [s, c] = [Math.sin(Math.PI / 6), Math.cos(Math.PI / 6)];
const lines = [];
for (let j = 0; j <= n; j++) {
  for (let i = 0; i <= n; i++) {
    if (kind === 'noisy') {
      const [x, y] = [i * 0.05, j * 0.05];
      const z = (0.3 * ((x - 2.5) ** 2 - (y - 2.5) ** 2)) / 20 + 0.004 * (rnd() - 0.5);
      lines.push(`v ${x} ${y} ${z}`);
    } else {
      const [a, b] = [-1 + (2 * i) / n, -1 + (2 * j) / n];
      const [x, y] = [c * a - s * b, s * a + c * b];
      lines.push(`v ${x} ${y} ${x * y}`);
    }
  }
}
for (let j = 0; j < n; j++) {
  for (let i = 0; i < n; i++) {
    const a = j * (n + 1) + i + 1;
    lines.push(`f ${a} ${a + 1} ${a + n + 2} ${a + n + 1}`);
  }
}
process.stdout.write(lines.join('\n') + '\n');
