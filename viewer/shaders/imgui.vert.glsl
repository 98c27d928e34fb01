#version 330 core
// Dear ImGui's vertices: positions in display coordinates (y down), texture coordinates,
// and a colour packed as four bytes.

uniform vec2 u_scale;      // display coordinates to clip space
uniform vec2 u_translate;

in vec2 in_position;
in vec2 in_uv;
in vec4 in_colour;

out vec2 v_uv;
out vec4 v_colour;

void main() {
    v_uv = in_uv;
    v_colour = in_colour;
    gl_Position = vec4(in_position * u_scale + u_translate, 0.0, 1.0);
}
