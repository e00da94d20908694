// davis-ag: the sky dome, an equirectangular image around the camera, at infinite distance.

uniform sampler2D sky;
uniform vec2 sky_scale;
uniform mat4 inverse_rotation_projection;  // clip space -> world direction (camera rotation only)
uniform float exposure;
uniform vec3 white_balance;

in vec2 ndc;

layout(location = 0) out vec4 out_colour;
layout(location = 1) out uint out_id;
layout(location = 2) out float out_depth;

const float PI = 3.14159265358979;

void main() {
    vec4 far = inverse_rotation_projection * vec4(ndc, 0.5, 1.0);  // a point on the ray; the eye is at 0
    vec3 d = normalize(far.xyz / far.w);
    // Longitude measured as Helios's sky dome maps it, latitude linear in the height of the direction.
    vec2 coordinate = vec2(0.5 - atan(d.x, -d.y) / (2.0 * PI), 0.5 * d.z + 0.5);
#ifdef HELIOS_LOOK
    vec3 c = texture(sky, fract(coordinate) * sky_scale).rgb;
#else
    vec3 c = textureLod(sky, vec2(fract(coordinate.x), coordinate.y), 0.0).rgb;
#endif
    vec3 encoded = encode_srgb(tone_curve(decode_srgb(c) * white_balance * exposure));
#ifdef SENSOR_NOISE
    encoded += sensor_noise();
#endif
    out_colour = vec4(encoded, 1.0);
    out_id = 0u;
    out_depth = 0.0;
}
