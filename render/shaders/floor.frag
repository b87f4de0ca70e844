// The bench's floor (issue 11): the cheapest fullscreen pass that reads one texture and
// writes the output. The blend pass is measured against it; it writes the blend's own target
// (SRGB8_ALPHA8 where the driver has EXT_texture_sRGB_decode: the store's encode is in both).
uniform highp sampler2D u_src;
layout(location = 0) out vec4 o_color;

void main()
{
    o_color = texelFetch(u_src, ivec2(gl_FragCoord.xy), 0);
}
