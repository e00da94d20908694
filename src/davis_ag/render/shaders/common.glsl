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

// Narkowicz's fit of the ACES curve, on radiance scaled by 0.6 as his note advises for the
// unmodified ACES response.
vec3 tone_curve(vec3 x) {
    x *= 0.6;
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
