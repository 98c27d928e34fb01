#version 330 core
// ImGui colours are display values already; the window framebuffer is not sRGB, so they are
// written as they are.

uniform sampler2D u_texture;

in vec2 v_uv;
in vec4 v_colour;

out vec4 f_colour;

void main() {
    f_colour = v_colour * texture(u_texture, v_uv);
}
