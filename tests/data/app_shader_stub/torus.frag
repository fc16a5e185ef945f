// A stand-in for the original web app's shaders (which are not ours to ship; see
// ../shared/peer-shaders.md): the same uniforms and output, so that gpu_bench's harness for them
// is tested. It draws the view direction.
uniform vec2 iResolution;
uniform float iTime;
uniform vec3 rayMarchCamPos;
uniform vec3 rayMarchCamFront;
uniform vec3 rayMarchCamUp;

void main() {
    vec2 uv = (gl_FragCoord.xy - 0.5 * iResolution) / min(iResolution.x, iResolution.y);
    vec3 right = normalize(cross(rayMarchCamFront, rayMarchCamUp));
    vec3 dir = normalize(rayMarchCamFront + uv.x * right + uv.y * rayMarchCamUp);
    gl_FragColor = vec4(0.5 + 0.5 * dir + 0.0 * iTime + 0.0 * rayMarchCamPos, 1.0);
}
