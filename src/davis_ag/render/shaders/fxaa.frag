#version 330 core
// davis-ag: antialiasing of the 1x colour image along silhouettes. Lottes's FXAA (its short form,
// with the quality version's early exit on low contrast), applied only where the depth jumps
// between neighbouring pixels: texture detail inside a surface is left as drawn, so the colour
// stays close to a multisampled frame while costing one full-screen pass instead of 4x samples.
// Written for davis-ag from the published algorithm; ids and depth never pass through here.

uniform sampler2D colour;       // the 1x colour, linear filtering, clamped to the edge
uniform sampler2D depths;       // the 1x depth along the optical axis, metres (0: nothing hit)
uniform vec2 texel;             // 1 / image size
uniform float depth_step = 0.02;          // a silhouette: a neighbour 2 % nearer or farther
uniform float edge_threshold = 0.125;     // FXAA's contrast thresholds (its "quality" defaults)
uniform float edge_threshold_min = 0.0625;

layout(location = 0) out vec4 out_colour;

const vec3 LUMA = vec3(0.299, 0.587, 0.114);
const float REDUCE_MIN = 1.0 / 128.0;
const float REDUCE_MUL = 1.0 / 8.0;
const float SPAN_MAX = 8.0;

vec3 at(vec2 p) { return texture(colour, p).rgb; }

// Depth at a pixel, clamped to the image (a fetch outside it is undefined).
float depth_at(ivec2 q) { return texelFetch(depths, clamp(q, ivec2(0), textureSize(depths, 0) - 1), 0).r; }

void main() {
    vec2 p = gl_FragCoord.xy * texel;
    ivec2 c = ivec2(gl_FragCoord.xy);
    vec3 middle = texelFetch(colour, c, 0).rgb;  // exact: a filtered look-up could round in neighbours
    float d = depth_at(c);
    vec4 n = vec4(depth_at(c + ivec2(1, 0)), depth_at(c - ivec2(1, 0)), depth_at(c + ivec2(0, 1)), depth_at(c - ivec2(0, 1)));
    if (all(lessThanEqual(abs(n - vec4(d)), vec4(depth_step * d)))) {
        out_colour = vec4(middle, 1.0);  // no silhouette here
        return;
    }
    float nw = dot(at(p + vec2(-1.0, -1.0) * texel), LUMA);
    float ne = dot(at(p + vec2(1.0, -1.0) * texel), LUMA);
    float sw = dot(at(p + vec2(-1.0, 1.0) * texel), LUMA);
    float se = dot(at(p + vec2(1.0, 1.0) * texel), LUMA);
    float m = dot(middle, LUMA);
    float lo = min(m, min(min(nw, ne), min(sw, se)));
    float hi = max(m, max(max(nw, ne), max(sw, se)));
    if (hi - lo < max(edge_threshold_min, hi * edge_threshold)) {
        out_colour = vec4(middle, 1.0);  // too little contrast to show a stair
        return;
    }
    vec2 direction = vec2(-((nw + ne) - (sw + se)), (nw + sw) - (ne + se));
    float reduce = max((nw + ne + sw + se) * (0.25 * REDUCE_MUL), REDUCE_MIN);
    float scale = 1.0 / (min(abs(direction.x), abs(direction.y)) + reduce);
    direction = clamp(direction * scale, vec2(-SPAN_MAX), vec2(SPAN_MAX)) * texel;
    vec3 narrow = 0.5 * (at(p + direction * (1.0 / 3.0 - 0.5)) + at(p + direction * (2.0 / 3.0 - 0.5)));
    vec3 wide = 0.5 * narrow + 0.25 * (at(p - direction * 0.5) + at(p + direction * 0.5));
    float luma = dot(wide, LUMA);
    out_colour = vec4((luma < lo || luma > hi) ? narrow : wide, 1.0);
}
