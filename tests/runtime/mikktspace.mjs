// MikkTSpace tangents by three.js's port of the reference (three/examples/jsm/libs/mikktspace.module.js,
// npm, pinned with three): the oracle matbake's own tangents are tested against.
//   node mikktspace.mjs POSITIONS NORMALS TEXCOORDS OUT
// Raw little-endian float32 files: 3, 3 and 2 values a corner, three corners a triangle; OUT gets
// 4 a corner (tangent xyz, bitangent sign).
import { readFileSync, writeFileSync } from 'node:fs';
import * as mikktspace from 'three/examples/jsm/libs/mikktspace.module.js';

const floats = (file) => new Float32Array(new Uint8Array(readFileSync(file)).buffer);  // a copy: aligned
const [positions, normals, texcoords, out] = process.argv.slice(2);
await mikktspace.ready;
const tangents = mikktspace.generateTangents(floats(positions), floats(normals), floats(texcoords));
writeFileSync(out, Buffer.from(tangents.buffer, tangents.byteOffset, tangents.byteLength));
