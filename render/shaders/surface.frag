// Pass 1 (light G-buffer) and the VPL pass's outer-surface cube map: world position with the
// object id + 1 (0 = empty texel), and the unit normal. A single-surface object (open, e.g. a
// shade of thickness 0) is two-sided: its normal is turned toward the viewer (the light).
in vec3 v_pos;
in vec3 v_nrm;
uniform int u_object;
uniform bool u_two_sided;
layout(location = 0) out vec4 o_pos;
layout(location = 1) out vec4 o_nrm;

void main()
{
    vec3 n = normalize(v_nrm);
    if (u_two_sided && !gl_FrontFacing)
        n = -n;
    o_pos = vec4(v_pos, float(u_object + 1));
    o_nrm = vec4(n, 0.0);
}
