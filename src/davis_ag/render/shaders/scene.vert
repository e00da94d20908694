#version 330 core
// davis-ag: the scene's triangles, in world coordinates (metres), one vertex buffer for all.

uniform mat4 view_projection;   // world -> clip space of the camera
uniform mat4 view;              // world -> camera space (camera looks down -z)
uniform mat4 light_projection;  // world -> [0, 1]^3 texture space of the shadow map

in vec3 in_position;
in vec2 in_uv;
in vec3 in_normal;
in vec4 in_colour;
in uint in_id;
in int in_texture;
in int in_mode;

out vec3 world_position;
out vec2 uv;
out vec3 vertex_normal;
out vec4 shadow_position;
out float view_depth;
flat out vec4 colour;
flat out uint primitive_id;
flat out int texture_layer;
flat out int texture_mode;

void main() {
    vec4 position = vec4(in_position, 1.0);
    gl_Position = view_projection * position;
    world_position = in_position;
    uv = in_uv;
    vertex_normal = in_normal;
    shadow_position = light_projection * position;
    view_depth = -(view * position).z;
    colour = in_colour;
    primitive_id = in_id;
    texture_layer = in_texture;
    texture_mode = in_mode;
}
