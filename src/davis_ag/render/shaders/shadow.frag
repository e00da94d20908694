// davis-ag: a leaf's transparent texels cast no shadow. In the helios look, as Helios's shadow
// pass: texels of alpha below 0.05 are transparent, and coordinates are scaled without wrapping.

in vec2 uv;
flat in int texture_layer;
flat in int texture_mode;

void main() {
    if (texture_mode == 0) {
        return;
    }
#ifdef HELIOS_LOOK
    if (texture(textures, vec3(uv * layer_scale[texture_layer], float(texture_layer))).a < 0.05) discard;
#else
    if (sample_layer(uv, texture_layer).a < 0.5) discard;
#endif
}
