// davis-ag: a leaf's transparent texels cast no shadow.

in vec2 uv;
flat in int texture_layer;
flat in int texture_mode;

void main() {
    if (texture_mode != 0 && sample_layer(uv, texture_layer).a < 0.5) discard;
}
