// A stand-in of ours for the original web app's shader generator (src/core/ShaderGenerator.js of
// RayMarchingFlatSurfaces, which is not ours to ship), so that peer_adapter is tested without
// the app: the same interface (a default-exported class with shaderTemplate, loadGeometryFile
// and generateShader), filling in ../../public/shader/template.frag for geometries whose walls
// are glued by translations, with hollow cubes and spheres.

const number = (x) => x.toFixed(8);
const vec3 = ([x, z]) => `vec3(${number(x)}, 0.0, ${number(z)})`;

function decoration(d) {
  // A 2D position is (x, z) at `height`; the app's older files give (x, y, z).
  const [x, y, z] = d.position.length === 2 ? [d.position[0], d.height || 0, d.position[1]]
                                            : d.position;
  let centre = [x, y, z];
  if (d.animation && d.animation.enabled) {
    // Where a circular animation stands at time 0.
    const [cx, cz] = d.animation.center || [0, 0];
    centre = [cx + d.animation.radius, y, cz];
  }
  const at = `p - vec3(${centre.map(number).join(', ')})`;
  if (d.type === 'hollow_cube') {
    const size = d.radius * (d.inner_ratio || 0.77);
    return `{ vec3 q = abs(${at}) - vec3(${number(size)});
      float box = length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
      df = min(df, max(box, ${number(d.radius)} - length(${at}))); }`;
  }
  if (d.type === 'sphere') return `df = min(df, length(${at}) - ${number(d.radius)});`;
  throw new Error(`the stand-in draws hollow cubes and spheres, not ${d.type}`);
}

export default class ShaderGenerator {
  constructor() {
    this.shaderTemplate = null;
  }

  async loadGeometryFile(geometryId) {
    throw new Error(`the stand-in reads no files: set loadGeometryFile (asked for ${geometryId})`);
  }

  async generateShader(geometryId) {
    const g = await this.loadGeometryFile(geometryId);
    if (!g.edges.every((e) => e.type === 'translation'))
      throw new Error('the stand-in glues walls by translations only');
    const walls = g.vertices.length - 1;
    const wallHeight = g.wallHeight || 2.0;
    const fog = g.fog_effect_strength || 0.01;
    const circle = (g.vertical_component || 'line').toLowerCase() === 'circle';
    const arrays = `const int gluingVector[NUM_WALLS] = int[NUM_WALLS](${g.gluing.join(', ')});
const vec3 transformVectors[NUM_WALLS] = vec3[NUM_WALLS](
    ${g.edges.map((e) => vec3(e.vector)).join(',\n    ')}
);
const vec3 wallNormals[NUM_WALLS] = vec3[NUM_WALLS](
    ${g.normals.map(vec3).join(',\n    ')}
);`;
    const shader = this.shaderTemplate
      .replace('{{WALL_HEIGHT}}', number(wallHeight))
      .replace('{{FOG_EFFECT_STRENGTH}}', number(fog))
      .replace('{{N}}', String(g.vertices.length))
      .replace('{{VERTICES}}', g.vertices.map(([x, z]) => `vec2(${number(x)}, ${number(z)})`)
        .join(',\n    '))
      .replace('{{NUM_WALLS}}', String(walls))
      .replace('{{TRANSFORMATION_ARRAYS}}', arrays)
      .replace('{{TRANSFORMATION_CODE}}',
               'pos += transformVectors[wallIdx] - 3.0 * eps * wallNormals[gluingVector[wallIdx]];')
      .replace('{{DECORATIONS}}', (g.decorations || []).map(decoration).join('\n    '))
      .replace('// {{VERTICAL_COMPONENT}}',
               circle ? `pos.y = mod(pos.y + wall_height, ${number(g.vertical_wrap_amount || 4.0)})` +
                          ' - wall_height;'
                      : '');
    return {
      shader,
      initialPosition: g.initialPosition || [0, 1, 0],
      wallHeight,
      fogEffectStrength: fog,
      verticalComponent: g.vertical_component || 'line',
    };
  }
}
