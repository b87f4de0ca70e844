// Copies the tone-mapped image to the default framebuffer (the projector).
in vec2 v_uv;
uniform highp sampler2D u_src;
layout(location = 0) out vec4 o_color;

void main()
{
    o_color = texture(u_src, v_uv);
}
