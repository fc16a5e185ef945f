// A stand-in of ours for the shader template of the original web app (public/shader/template.frag
// of RayMarchingFlatSurfaces, which is not ours to ship), so that peer_adapter is tested without
// the app: the app's uniforms, its output, and the lines the adapter edits, around a small sphere
// tracer of a floor plan whose walls translate rays. src/core/ShaderGenerator.js beside it fills
// in the {{...}} placeholders.
uniform vec2 iResolution;
uniform float iTime;
uniform vec3 rayMarchCamPos;
uniform vec3 rayMarchCamFront;
uniform vec3 rayMarchCamUp;

const float eps = 0.00001;
const float tMax = 100.0;
const float wall_height = {{WALL_HEIGHT}};
const float fog_effect_strength = {{FOG_EFFECT_STRENGTH}};

// The floor plan in (x, z), closed: the last vertex repeats the first.
const int N = {{N}};
const vec2 polygonVertices[N] = vec2[N](
    {{VERTICES}}
);
const int NUM_WALLS = {{NUM_WALLS}};

{{TRANSFORMATION_ARRAYS}}

// Wall k: the segment from vertex k to k + 1, from y = -wall_height to wall_height.
float wallDistance(vec3 p, int k) {
    vec2 a = polygonVertices[k];
    vec2 d = polygonVertices[k + 1] - a;
    vec2 q = p.xz - a;
    vec2 w = vec2(length(q - clamp(dot(q, d) / dot(d, d), 0.0, 1.0) * d), abs(p.y) - wall_height);
    return length(max(w, 0.0)) + min(max(w.x, w.y), 0.0);
}

// The nearest wall: its distance (x) and index (y).
vec2 nearestWall(vec3 p) {
    vec2 nearest = vec2(1000.0, -1.0);
    for (int k = 0; k < NUM_WALLS; k++) {
        float d = wallDistance(p, k);
        if (d < nearest.x) nearest = vec2(d, float(k));
    }
    return nearest;
}

float sdDecorations(vec3 p) {
    float df = 1000.0;
    {{DECORATIONS}}
    return df;
}

float sdf(vec3 p) {
    return min(nearestWall(p).x, sdDecorations(p));
}

vec3 decorationNormal(vec3 p) {
    vec2 h = vec2(0.0001, 0.0);
    return normalize(vec3(sdDecorations(p + h.xyy) - sdDecorations(p - h.xyy),
                          sdDecorations(p + h.yxy) - sdDecorations(p - h.yxy),
                          sdDecorations(p + h.yyx) - sdDecorations(p - h.yyx)));
}

void applyTransformation(inout vec3 pos, inout vec3 ray, int wallIdx) {
    {{TRANSFORMATION_CODE}}
}

void main() {
    vec3 front = normalize(rayMarchCamFront);
    vec3 right = normalize(cross(front, rayMarchCamUp));
    vec3 up = cross(right, front);
    vec2 uv = (gl_FragCoord.xy - 0.5 * iResolution) / min(iResolution.x, iResolution.y);
    float fov = radians(75.0);
    vec3 ray = normalize(front + tan(0.5 * fov) * (uv.x * right + uv.y * up));

    vec3 pos = rayMarchCamPos;
    float t = 0.0;
    float collision_count = 0.0;
    float finalHitID = -1.0;  // 1000: a decoration
    for (int i = 0; i < 2000; i++) {
        float sceneDist = sdf(pos);
        pos += sceneDist * ray;
        if (abs(sceneDist) < eps) {
            vec2 wall = nearestWall(pos);
            if (wall.x < sdDecorations(pos)) {
                applyTransformation(pos, ray, int(wall.y));
                collision_count += 1.0;
                continue;
            }
            finalHitID = 1000.0;
            break;
        }
        t += sceneDist;
        // {{VERTICAL_COMPONENT}}
        if (t > tMax) {
            finalHitID = -1.0;
            break;
        }
    }

    vec3 color = finalHitID >= 1000.0 ? 0.5 + 0.5 * decorationNormal(pos) : vec3(1.0);
    gl_FragColor = vec4(color, 1.0) - collision_count * vec4(fog_effect_strength);
}
