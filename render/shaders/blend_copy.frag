// The blend pass's display copy (render/passes/blend.h): the LR_COPY_N per-light RGBA32F
// images into RGBA16F layers, once per change of the images, so that each dimmer or flicker
// frame reads half the bytes. Clamped to fp16's largest finite value: an overflow would store
// infinity, which the ACES curve turns into NaN (inf / inf) rather than white.
#if !defined(LR_COPY_N)
#error blend_copy.frag needs LR_COPY_N
#endif
uniform highp sampler2DArray u_images;
layout(location = 0) out vec4 o_layer0;
#if LR_COPY_N >= 2
layout(location = 1) out vec4 o_layer1;
#endif
#if LR_COPY_N >= 3
layout(location = 2) out vec4 o_layer2;
#endif
#if LR_COPY_N >= 4
layout(location = 3) out vec4 o_layer3;
#endif

const float LR_HALF_MAX = 65504.0;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    o_layer0 = min(texelFetch(u_images, ivec3(p, 0), 0), vec4(LR_HALF_MAX));
#if LR_COPY_N >= 2
    o_layer1 = min(texelFetch(u_images, ivec3(p, 1), 0), vec4(LR_HALF_MAX));
#endif
#if LR_COPY_N >= 3
    o_layer2 = min(texelFetch(u_images, ivec3(p, 2), 0), vec4(LR_HALF_MAX));
#endif
#if LR_COPY_N >= 4
    o_layer3 = min(texelFetch(u_images, ivec3(p, 3), 0), vec4(LR_HALF_MAX));
#endif
}
