// davis-ag: shading of scene triangles. Outputs colour, primitive id (UUID + 1) and the depth
// along the optical axis in one pass; the id-only variant (IDS_ONLY) skips the lighting, the
// NO_DEPTH variant the depth (for callers that do not need it: one output and one value less).

uniform sampler2D shadow_map;
uniform vec3 sun;               // unit vector towards the sun
uniform vec3 eye;               // camera position
uniform float exposure;
uniform float sun_strength;     // factor on the direct light (randomised appearance; 1 otherwise)
uniform vec3 white_balance;     // gains on linear red, green and blue (1, 1, 1 otherwise)
uniform vec3 sky_ambient;
uniform vec3 ground_ambient;
uniform vec4 material;          // ambient, diffuse, specular weights and shininess
uniform float shadow_bias;
uniform float light_depth_range; // metres from the shadow map's depth 0 to depth 1
uniform mat4 shadow_box;        // world -> [0, 1]^3 of the region that can be in shadow (Helios look)

in vec3 world_position;
in vec2 uv;
in vec3 vertex_normal;
in vec4 shadow_position;
in float view_depth;
flat in vec4 colour;             // linear albedo
flat in uint primitive_id;
flat in int texture_layer;
flat in int texture_mode;

#ifdef IDS_ONLY
layout(location = 0) out uint out_id;
layout(location = 1) out float out_depth;
#else
layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_id;
#ifndef NO_DEPTH
layout(location = 2) out float out_depth;
#endif
#endif

// Helios computes shadows only inside a box around its camera's view volume (shadow_box); the
// default look shades everywhere, so it leaves the box's tests out rather than run them on every
// fragment (llvmpipe runs a branch's both sides).
float sunlit(vec3 normal) {
#ifdef HELIOS_LOOK
    vec3 b = (shadow_box * vec4(world_position, 1.0)).xyz;
    if (dot(normal, sun) <= 0.0 || any(lessThan(b, vec3(0.0))) || any(greaterThan(b, vec3(1.0)))) {
        return 1.0;
    }
#else
    if (dot(normal, sun) <= 0.0) {
        return 1.0;
    }
#endif
    vec3 p = shadow_position.xyz / shadow_position.w;
    if (any(lessThan(p, vec3(0.0))) || p.x > 1.0 || p.y > 1.0) {
        return 1.0;  // outside the casters' box: nothing can shade it
    }
    // Receivers below every caster (the ground) are clamped to the far plane and still tested.
    float occluder_depth = texture(shadow_map, p.xy).r;
    if (occluder_depth >= min(p.z, 1.0) - shadow_bias) {
        return 1.0;
    }
#ifdef HELIOS_LOOK
    // Helios's map holds only casters inside its box: one nearer the sun than the box casts nothing.
    vec3 occluder = world_position + sun * ((p.z - occluder_depth) * light_depth_range);
    return (shadow_box * vec4(occluder, 1.0)).z < 0.0 ? 1.0 : 0.0;
#else
    return 0.0;
#endif
}

void main() {
    // Colours arrive linear: vertex colours boosted and decoded once per scene, texels decoded
    // when the textures were made.
    vec4 albedo = colour;
    // One look-up serves both textured modes: llvmpipe would run a look-up written in each branch.
    vec4 texel = sample_layer(uv, texture_layer);
    if (texture_mode == 1) {
        albedo = texel;
        if (albedo.a < 0.5) discard;
    } else if (texture_mode == 2 && texel.a < 0.5) {
        discard;
    }
    out_id = primitive_id;
#ifndef NO_DEPTH
    out_depth = view_depth;
#endif
#ifndef IDS_ONLY
    vec3 normal = normalize(vertex_normal);
    vec3 to_eye = normalize(eye - world_position);
    // Ambient light reaches the side being looked at; direct light only the side facing the sun.
    vec3 facing = dot(normal, to_eye) < 0.0 ? -normal : normal;
    vec3 ambient = material.x * mix(ground_ambient, sky_ambient, 0.5 * facing.z + 0.5) * albedo.rgb;
    float lambert = max(dot(normal, sun), 0.0);
    vec3 direct = material.y * lambert * albedo.rgb;
    if (lambert > 0.0) {
        direct += vec3(material.z * pow(max(dot(normal, normalize(sun + to_eye)), 0.0), material.w));
    }
    vec3 radiance = vec3(1.0, 0.9, 0.8) * (ambient + sunlit(normal) * sun_strength * direct);
    vec3 encoded = encode_srgb(tone_curve(radiance * white_balance * exposure));
#ifdef SENSOR_NOISE
    encoded += sensor_noise();  // the 8-bit attachment clamps to [0, 1] and rounds
#endif
    out_colour = vec4(encoded, 1.0);
#endif
}
