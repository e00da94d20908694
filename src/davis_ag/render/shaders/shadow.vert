#version 330 core
// davis-ag: depth of the shadow casters seen from the sun.

uniform mat4 light_projection;

in vec3 in_position;
in vec2 in_uv;
in int in_texture;
in int in_mode;

out vec2 uv;
flat out int texture_layer;
flat out int texture_mode;

void main() {
    vec4 p = light_projection * vec4(in_position, 1.0);
    gl_Position = vec4(p.xyz * 2.0 - 1.0, 1.0);  // the matrix maps to [0, 1]^3; GL wants [-1, 1]^3
    uv = in_uv;
    texture_layer = in_texture;
    texture_mode = in_mode;
}
