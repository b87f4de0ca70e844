// The bench's floor (issue 11): the cheapest fullscreen pass that reads one texture and
// writes the output. The blend pass is measured against it.
uniform highp sampler2D u_src;
layout(location = 0) out vec4 o_color;

void main()
{
    o_color = texelFetch(u_src, ivec2(gl_FragCoord.xy), 0);
}
