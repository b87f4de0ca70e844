// Depth-only prepass of the radiosity maps (seed 003 Sec. 3.2): the accumulation pass then
// runs with depth writes off and GL_LEQUAL, so that blending sees each texel's visible
// surface once.
void main()
{
}
