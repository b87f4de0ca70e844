// The receivers' light on the objects, fragment side (render/bounce/objlight.h): B_recv per
// light at unit intensity from the interpolated E+ and E- (lib/recv_light_vert.glsl),
// B = kR E+ + kT E- on the front, kR E- + kT E+ on an open surface's back, kR and kT the
// object's factors times the image's scale (u_rl_r, u_rl_t: render/passes/irradiance.c).
// Composition adds F_t(w_o) B / pi like the maps' B (seed 003 Eq. 5). Zero when off (the
// varyings are).
uniform vec3 u_rl_r[LR_MAX_LIGHTS];
uniform vec3 u_rl_t[LR_MAX_LIGHTS];
in vec3 v_rlp[LR_MAX_LIGHTS];
in vec3 v_rlm[LR_MAX_LIGHTS];

vec3 lr_rl_B(int l, vec3 ep, vec3 em, bool back)
{
    return back ? u_rl_r[l] * em + u_rl_t[l] * ep : u_rl_r[l] * ep + u_rl_t[l] * em;
}
