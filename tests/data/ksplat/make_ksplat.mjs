// Writes a .ksplat with GaussianSplats3D's own generator (the steps of its util/create-ksplat.js, which the
// npm package does not ship): node make_ksplat.mjs INPUT.ply OUTPUT.ksplat LEVEL SH_DEGREE
import * as GaussianSplats3D from '@mkkellogg/gaussian-splats-3d';
import * as fs from 'fs';
const [input, output, level, shDegree] = process.argv.slice(2);
const file = fs.readFileSync(input);
const bytes = file.buffer.slice(file.byteOffset, file.byteOffset + file.byteLength);
const splats = GaussianSplats3D.PlyParser.parseToUncompressedSplatArray(bytes, Number(shDegree));
const generator = GaussianSplats3D.SplatBufferGenerator.getStandardGenerator(0, Number(level), 0);
const buffer = generator.generateFromUncompressedSplatArray(splats);
fs.writeFileSync(output, Buffer.from(buffer.bufferData));
console.log(`${output}: ${buffer.getSplatCount()} splats, level ${level}, SH degree ${shDegree}`);
