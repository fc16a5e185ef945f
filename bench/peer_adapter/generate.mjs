// The original web app's shader for one of its geometry files, made by the app's own generator
// (src/core/ShaderGenerator.js of a checkout of RayMarchingFlatSurfaces), for peer_adapter.
//
//   node generate.mjs APP_DIR GEOMETRY_JSON
//
// prints {shader, initialPosition, wallHeight, fogEffectStrength, verticalComponent} as JSON.
// The generator fetches its template and geometries over HTTP in the browser; here they are
// read from the checkout and the given file instead of calling initialize().
import {copyFileSync, mkdtempSync, readFileSync, rmSync} from 'node:fs';
import {tmpdir} from 'node:os';
import {join} from 'node:path';
import {pathToFileURL} from 'node:url';

const [app, geometryFile] = process.argv.slice(2);
if (!app || !geometryFile) {
  console.error('usage: node generate.mjs APP_DIR GEOMETRY_JSON');
  process.exit(2);
}
// Whatever the generator logs must not mix with the JSON on stdout.
console.log = console.error;

async function generate() {
  const geometry = JSON.parse(readFileSync(geometryFile, 'utf8'));
  const template = readFileSync(join(app, 'public', 'shader', 'template.frag'), 'utf8');
  // The app's package does not declare "type": "module", so Node reads its .js files as
  // CommonJS; a copy named .mjs loads as the ES module it is.
  const folder = mkdtempSync(join(tmpdir(), 'flatmarch-peer-generator-'));
  try {
    const module = join(folder, 'ShaderGenerator.mjs');
    copyFileSync(join(app, 'src', 'core', 'ShaderGenerator.js'), module);
    const {default: ShaderGenerator} = await import(pathToFileURL(module).href);
    const generator = new ShaderGenerator();
    generator.shaderTemplate = template;
    generator.loadGeometryFile = async () => geometry;
    const generated = await generator.generateShader(geometry.id ?? 'geometry');
    return {
      shader: generated.shader,
      initialPosition: generated.initialPosition,
      wallHeight: generated.wallHeight,
      fogEffectStrength: generated.fogEffectStrength,
      verticalComponent: generated.verticalComponent,
    };
  } finally {
    rmSync(folder, {recursive: true, force: true});
  }
}

try {
  process.stdout.write(JSON.stringify(await generate()) + '\n');
} catch (error) {
  // One line for the adapter to pass on.
  console.error(`the app's shader generator failed: ${error.message}`.replace(/\s+/g, ' '));
  process.exit(1);
}
