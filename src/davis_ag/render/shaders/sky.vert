#version 330 core
// davis-ag: one triangle covering the screen; the sky behind everything.

out vec2 ndc;

void main() {
    ndc = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(ndc, 1.0, 1.0);
}
