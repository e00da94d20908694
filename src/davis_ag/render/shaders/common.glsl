// davis-ag: what the scene and sky shaders share: texture look-ups, colour transfer and tone curve.
// Written for davis-ag from the lighting model Helios's Visualizer documents (Blinn-Phong with a sky
// and ground ambient, a shadow map, sRGB decoding, an ACES-fitted tone curve); no Helios shader text.

// The look is chosen when the program is compiled (HELIOS_LOOK defined: Helios's texture handling,
// wrap by fract, nearest texel), not by a uniform: llvmpipe runs both sides of every branch under
// a mask, so a branch on a uniform would sample the textures of both looks for every fragment.
uniform sampler2DArray textures;
uniform vec2 layer_scale[64];   // used part of each layer (Helios look: images keep their own size)

vec4 sample_layer(vec2 coordinate, int layer) {
#ifdef HELIOS_LOOK
    return texture(textures, vec3(fract(coordinate) * layer_scale[layer], float(layer)));
#else
    // Colour trilinear from the mipmaps; alpha from the full-resolution image, so a leaf keeps its
    // outline at a distance (averaged alpha would thin it below the 0.5 threshold).
    vec3 at = vec3(coordinate, float(layer));
    return vec4(texture(textures, at).rgb, textureLod(textures, at, 0.0).a);
#endif
}

vec3 decode_srgb(vec3 c) {
    return mix(pow((c + 0.055) / 1.055, vec3(2.4)), c / 12.92, vec3(lessThanEqual(c, vec3(0.04045))));
}

vec3 encode_srgb(vec3 c) {
    c = max(c, vec3(0.0));
    return mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, c * 12.92, vec3(lessThanEqual(c, vec3(0.0031308))));
}

#ifdef SENSOR_NOISE
// Sensor noise (randomised appearance), compiled in only where asked for: Gaussian, in grey levels
// of the 8-bit output, per pixel and channel from an integer hash (PCG) of the pixel and the
// view's seed. Each channel sums the four bytes of one hash (Irwin-Hall: near Gaussian, within
// +-3.5 sigma): three hashes and some adds per fragment, cheaper on a software rasteriser than
// Box-Muller's logarithms and cosines, and no pass or read-back of its own.
uniform float noise_sigma;      // standard deviation, grey levels of 255
uniform uint noise_seed;        // one per view

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float byte_sum(uint h) {
    return float((h & 255u) + ((h >> 8u) & 255u) + ((h >> 16u) & 255u) + (h >> 24u));
}

vec3 sensor_noise() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = pcg_hash(p.x ^ pcg_hash(p.y ^ noise_seed));
    uint h2 = pcg_hash(h), h3 = pcg_hash(h2);
    // Four bytes: mean 510, standard deviation 2 * 73.9 = 147.8 grey levels.
    vec3 sums = vec3(byte_sum(h), byte_sum(h2), byte_sum(h3));
    return (sums - 510.0) * (noise_sigma / (147.8 * 255.0));
}
#endif

// Narkowicz's fit of the ACES curve, on radiance scaled by 0.6 as his note advises for the
// unmodified ACES response.
vec3 tone_curve(vec3 x) {
    x *= 0.6;
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
