// Converts the npm `bunny` package (public domain; JS arrays `positions` and `cells`)
// into an ASCII PLY file that dyncull's loader reads. Usage: node bunny_npm_to_ply.js PKGDIR OUT.ply
'use strict';
const fs = require('fs');
const path = require('path');
const [pkgDir, out] = process.argv.slice(2);
if (!pkgDir || !out) {
  console.error('usage: node bunny_npm_to_ply.js PKGDIR OUT.ply');
  process.exit(2);
}
const bunny = require(path.resolve(pkgDir));
const lines = [
  'ply', 'format ascii 1.0', 'comment npm package bunny@1.0.1 (public domain)',
  `element vertex ${bunny.positions.length}`, 'property float x', 'property float y', 'property float z',
  `element face ${bunny.cells.length}`, 'property list uchar int vertex_indices', 'end_header',
];
for (const p of bunny.positions) lines.push(p.join(' '));
for (const c of bunny.cells) lines.push(`${c.length} ${c.join(' ')}`);
fs.writeFileSync(out, lines.join('\n') + '\n');
console.log(`wrote ${out}: ${bunny.positions.length} vertices, ${bunny.cells.length} triangles`);
