// Rhino .3dm files, read and written with McNeel's rhino3dm (OpenNURBS compiled to wasm), in a
// worker of their own: rhino3dm's bindings build functions from strings (embind), which the
// page's policy forbids, so only this worker is served with 'unsafe-eval' (xtask serve), and
// rhino3dm loads only when a .3dm is opened or written.
// Protocol: in  {id, read: bytes} | {id, write: {unit, layers: [{name, positions, faces}], name}}
//           out {id, design: {unit, kind, name, text, note}} | {id, bytes, degenerate} | {id, error}
import rhino3dm from './vendor/node_modules/rhino3dm/rhino3dm.module.js';

const rhinoReady = rhino3dm();

// Dupin's length units and Rhino's unit systems.
const UNITS = [['mm', 'Millimeters'], ['cm', 'Centimeters'], ['m', 'Meters'], ['in', 'Inches'], ['ft', 'Feet']];

// The layers of a written file, after Dupin's layer names.
const LAYERS = {
  panels: ['Dupin panels', { r: 90, g: 160, b: 220, a: 255 }],
  offset: ['Dupin offset', { r: 230, g: 160, b: 60, a: 255 }],
  beams: ['Dupin beams', { r: 120, g: 120, b: 120, a: 255 }],
};
const OUTLINES = ['Dupin panel outlines', { r: 20, g: 40, b: 80, a: 255 }];

/** The file's unit as Dupin names it; null for "no unit"; an error for another unit. */
function unitOf(rhino, doc) {
  const system = doc.settings().modelUnitSystem;
  if (system.value === rhino.UnitSystem.None.value) return null;
  for (const [name, rhinoName] of UNITS) if (system.value === rhino.UnitSystem[rhinoName].value) return name;
  const label = Object.keys(rhino.UnitSystem).find((k) => rhino.UnitSystem[k]?.value === system.value) ?? `#${system.value}`;
  throw new Error(`its unit system is ${label}; Dupin reads mm, cm, m, in and ft: change the model units in Rhino and save again`);
}

/** A NURBS surface as Dupin's JSON (docs/nurbs-json.md): control points Euclidean, weights
 * apart (rhino3dm hands out homogeneous points (wx, wy, wz, w)), knots in Rhino's convention. */
function surfaceJson(s, unit) {
  const pts = s.points();
  const rational = s.isRational;
  const controlPoints = [];
  const weights = [];
  for (let i = 0; i < pts.countU; i++) {
    const row = [];
    const wrow = [];
    for (let j = 0; j < pts.countV; j++) {
      const [x, y, z, w] = pts.get(i, j);
      const ww = rational ? w : 1;
      row.push([x / ww, y / ww, z / ww]);
      wrow.push(ww);
    }
    controlPoints.push(row);
    weights.push(wrow);
  }
  const json = {
    degree_u: s.degree(0),
    degree_v: s.degree(1),
    knots_u: s.knotsU().toList(),
    knots_v: s.knotsV().toList(),
    control_points: controlPoints,
  };
  if (rational) json.weights = weights;
  if (unit) json.unit = unit;
  return JSON.stringify(json);
}

/** Every mesh of the file as one OBJ, welded by exact position (Rhino keeps a mesh's parts and
 * separate meshes unwelded). Quads stay quads; a triangle is a quad with its last corner
 * repeated. */
function meshesObj(meshes, fileName) {
  const index = new Map();
  const vertices = [];
  const faces = [];
  for (const m of meshes) {
    const vs = m.vertices();
    const local = [];
    for (let i = 0; i < vs.count; i++) {
      const p = vs.get(i);
      const key = `${p[0]},${p[1]},${p[2]}`;
      let k = index.get(key);
      if (k === undefined) { k = vertices.length; index.set(key, k); vertices.push(p); }
      local.push(k + 1);
    }
    const fs = m.faces();
    for (let i = 0; i < fs.count; i++) {
      const [a, b, c, d] = fs.get(i);
      faces.push(c === d ? [local[a], local[b], local[c]] : [local[a], local[b], local[c], local[d]]);
    }
  }
  const lines = [`# from ${fileName.replace(/[\r\n]/g, ' ')} (rhino3dm)`];
  for (const p of vertices) lines.push(`v ${p[0]} ${p[1]} ${p[2]}`);
  for (const f of faces) lines.push(`f ${f.join(' ')}`);
  return lines.join('\n') + '\n';
}

/** The design a .3dm holds: its first NURBS surface or single-face Brep (as NURBS JSON), else
 * all its meshes (as one OBJ). */
async function read(bytes, fileName) {
  const rhino = await rhinoReady;
  const doc = rhino.File3dm.fromByteArray(bytes);
  if (!doc) throw new Error('not a Rhino .3dm file (rhino3dm could not read it; is it truncated or another format?)');
  const unit = unitOf(rhino, doc);
  const objects = doc.objects();
  const meshes = [];
  const skipped = new Map();
  let surface = null;
  let extraSurfaces = 0;
  for (let i = 0; i < objects.count; i++) {
    const o = objects.get(i);
    const g = o.geometry();
    const kind = g?.constructor?.name ?? 'unknown';
    let s = null;
    if (kind === 'NurbsSurface') s = g;
    else if (kind === 'Brep' && g.faces().count === 1) s = g.faces().get(0).toNurbsSurface();
    else if (kind === 'Extrusion' || kind === 'PlaneSurface' || kind === 'RevSurface' || kind === 'SumSurface') s = g.toNurbsSurface?.() ?? null;
    if (s) {
      if (surface) extraSurfaces += 1;
      else surface = { json: surfaceJson(s, unit), name: o.attributes().name || `object ${i + 1}` };
    } else if (kind === 'Mesh') {
      meshes.push(g);
    } else {
      skipped.set(kind, (skipped.get(kind) ?? 0) + 1);
    }
  }
  const notes = [];
  if (surface && extraSurfaces) notes.push(`${extraSurfaces} more surface(s) left out`);
  if (surface && meshes.length) notes.push(`${meshes.length} mesh(es) left out`);
  if (skipped.size) notes.push(`skipped ${[...skipped].map(([k, n]) => `${n} ${k}`).join(', ')}`);
  if (surface) return { unit, kind: 'surface', name: surface.name, text: surface.json, note: notes.join('; ') };
  if (meshes.length) return { unit, kind: 'mesh', name: `${meshes.length} mesh(es)`, text: meshesObj(meshes, fileName), note: notes.join('; ') };
  throw new Error(`no NURBS surface, single-face Brep or mesh in it${skipped.size ? ` (${notes.join('; ')})` : ''}: save the design's surface or mesh into the .3dm`);
}

/** The plane of a planar polygon `pts` for Brep.createTrimmedPlane: origin at the centroid,
 * normal by Newell's formula (exact for a planar polygon, any convexity), x along the first
 * edge. */
function panelPlane(pts) {
  const n = pts.length;
  const origin = [0, 1, 2].map((k) => pts.reduce((s, p) => s + p[k], 0) / n);
  const z = [0, 0, 0];
  for (let i = 0; i < n; i++) {
    const [a, b] = [pts[i], pts[(i + 1) % n]];
    z[0] += (a[1] - b[1]) * (a[2] + b[2]);
    z[1] += (a[2] - b[2]) * (a[0] + b[0]);
    z[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  const unit = (v) => { const l = Math.hypot(...v); return v.map((c) => c / l); };
  const zAxis = unit(z);
  const e = [0, 1, 2].map((k) => pts[1][k] - pts[0][k]);
  const d = e[0] * zAxis[0] + e[1] * zAxis[1] + e[2] * zAxis[2];
  const xAxis = unit(e.map((c, k) => c - d * zAxis[k]));
  const yAxis = [zAxis[1] * xAxis[2] - zAxis[2] * xAxis[1], zAxis[2] * xAxis[0] - zAxis[0] * xAxis[2], zAxis[0] * xAxis[1] - zAxis[1] * xAxis[0]];
  return { origin, xAxis, yAxis, zAxis };
}

/** A .3dm of the panels: each panel a planar surface (a plane trimmed by the panel's polygon,
 * what Rhino's PlanarSrf makes) named by its number on layer `Dupin panels`, its closed outline
 * on `Dupin panel outlines`; offsets and beams as planar surfaces on layers of their own; the
 * file in the design's unit. */
async function write({ unit, layers }) {
  const rhino = await rhinoReady;
  const doc = new rhino.File3dm();
  doc.settings().modelUnitSystem = rhino.UnitSystem[UNITS.find(([u]) => u === unit)?.[1] ?? 'Meters'];
  doc.applicationName = 'Dupin';
  const outlineLayer = doc.layers().addLayer(OUTLINES[0], OUTLINES[1]);
  let degenerate = 0;
  for (const layer of layers) {
    const [layerName, color] = LAYERS[layer.name] ?? [`Dupin ${layer.name}`, { r: 0, g: 0, b: 0, a: 255 }];
    const layerIndex = doc.layers().addLayer(layerName, color);
    const p = layer.positions;
    layer.faces.forEach((face, k) => {
      const corners = face.map((v) => [p[3 * v], p[3 * v + 1], p[3 * v + 2]]);
      const outline = new rhino.PolylineCurve([...corners, corners[0]]);
      const name = layer.name === 'panels' ? String(k + 1) : `${layer.name} ${k + 1}`;
      const brep = rhino.Brep.createTrimmedPlane(panelPlane(corners), outline);
      if (brep) {
        const a = new rhino.ObjectAttributes();
        a.name = name;
        a.layerIndex = layerIndex;
        doc.objects().addBrep(brep, a);
        a.delete();
        brep.delete();
      } else {
        degenerate += 1;
      }
      if (layer.name === 'panels') {
        const a = new rhino.ObjectAttributes();
        a.name = name;
        a.layerIndex = outlineLayer;
        doc.objects().add(outline, a);
        a.delete();
      }
      outline.delete();
    });
  }
  const bytes = doc.toByteArray();
  doc.delete();
  return { bytes, degenerate };
}

self.onmessage = async (e) => {
  const { id, read: bytes, write: panels, name } = e.data;
  try {
    if (bytes) postMessage({ id, design: await read(bytes, name ?? 'design.3dm') });
    else {
      const { bytes: out, degenerate } = await write(panels);
      postMessage({ id, bytes: out, degenerate }, [out.buffer]);
    }
  } catch (err) {
    postMessage({ id, error: err?.message ?? String(err) });
  }
};
