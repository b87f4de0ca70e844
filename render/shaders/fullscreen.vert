// One triangle covering the viewport, for passes that shade every texel of a target
// (draw with lr_gl_draw_fullscreen: three vertices, no buffers). Vertices (-1,-1), (3,-1),
// (-1,3): the clip square [-1,1]^2 lies inside, and unlike a two-triangle quad no fragment
// along a diagonal is shaded twice.
out vec2 v_uv; // 0..1 across the viewport, (0,0) at the bottom-left texel corner

void main()
{
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    v_uv = p * 0.5 + 0.5;
    gl_Position = vec4(p, 0.0, 1.0);
}
