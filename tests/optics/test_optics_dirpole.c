/* Directional dipole S_d of [14] (Frisvad, Hachisuka, Kjeldsen 2014): the required marble values,
 * oblique light and curved surfaces against an independent implementation, invariance under
 * rigid motions and mm <-> m scaling, and the hard cases (r -> 0, x_o straight through a shell,
 * albedo' -> 1, albedo' -> 0, eta = 1, eta < 1 with total internal reflection, grazing light,
 * coefficients 1e-6..1e3 mm^-1, rejected input). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/support/near.h"
#include <math.h>
#include <string.h>

#include "render/optics/optics.h"

static const lr_medium marble = {{0.0021, 0.0041, 0.0071}, {2.19, 2.62, 3.00}, 1.5, 0.0};
static const lr_vec3 Z = {0.0, 0.0, 1.0};
static const lr_vec3 O = {0.0, 0.0, 0.0};

static lr_coeffs derive(const lr_medium *m)
{
    lr_coeffs c;
    lr_err e;
    lr_err_clear(&e);
    if (lr_coeffs_derive(m, &c, &e) != LR_OK)
        fail_msg("derive: %s", e.msg);
    return c;
}

struct dp_case {
    const char *name;
    double ssp[3], sa[3], eta;
    lr_vec3 xi, ni, wi, xo, no;
    double sd[3];
    double scale[3];
};

struct dp_grid_case {
    double sa, ssp, r, sd, scale;
};

/* tests/support/gen_dirpole_ref.py: the directional dipole of /work/ref/dirpole_ref.py (an independent
 * pure-Python port of [14]) in 50-digit mpmath arithmetic, cross-checked against the
 * double-precision reference itself to 1e-9 of the source magnitude where it is defined.
 * scale = |real source term| + |virtual source term| (the size of the cancellation). */
static const struct dp_case dp_cases[] = {
    {"oblique 45deg toward +x, x_o=(0.5,0,0)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {0.5, 0, 0}, {0, 0, 1},
     {3.1636587333377322e-2, 3.4385487282899521e-2, 3.6492376012084844e-2}, {3.9026246863938379e-2, 4.3757844444801036e-2, 4.7295614268187365e-2}},
    {"oblique 45deg toward +x, x_o=(1,0,0)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {1, 0, 0}, {0, 0, 1},
     {1.1339205311613674e-2, 1.2213212956905194e-2, 1.2674292764100839e-2}, {1.8313794922408174e-2, 2.0838656115222085e-2, 2.2341201220657256e-2}},
    {"oblique 45deg toward +x, x_o=(2,0,0)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {2, 0, 0}, {0, 0, 1},
     {3.6877144832775812e-3, 3.6348434606001629e-3, 3.4339755282119665e-3}, {9.5649645927991431e-3, 1.0397958639018523e-2, 1.0439480787316194e-2}},
    {"oblique 45deg, x_o behind the light (-1,0,0)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {-1, 0, 0}, {0, 0, 1},
     {1.8019780181962295e-2, 1.8949678179536662e-2, 1.9319461826564177e-2}, {2.5502006756456297e-2, 2.8376859725629976e-2, 3.0083021287926341e-2}},
    {"oblique 45deg, x_o sideways (0,1,0)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {0, 1, 0}, {0, 0, 1},
     {1.4566229499558606e-2, 1.5491005014316472e-2, 1.5920890385609152e-2}, {2.1794637592202857e-2, 2.4517317366521575e-2, 2.6136124344568442e-2}},
    {"grazing 80deg in y-z, x_o=(0.7,-0.4,0)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0, 0.98480775301220813, 0.17364817766693044},
     {0.69999999999999996, -0.40000000000000002, 0}, {0, 0, 1},
     {2.341747912755091e-2, 2.5055061960668232e-2, 2.6003388011876482e-2}, {3.1151667805550237e-2, 3.4874759388216053e-2, 3.7319992967557051e-2}},
    {"convex sphere R=5, x_o at 0.1 rad, oblique light",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 5}, {0, 0, 1}, {0.31799936400190792, 0.42399915200254396, 0.84799830400508791},
     {0.49916708323414077, 0, 4.9750208263901294}, {0.099833416646828155, 0, 0.99500416527802582},
     {3.8577092411160375e-2, 4.2375857177375969e-2, 4.514574151515e-2}, {4.5957215983818724e-2, 5.1762542990100306e-2, 5.5997162349261857e-2}},
    {"convex sphere R=5, x_o at 0.3 rad, oblique light",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 5}, {0, 0, 1}, {0.31799936400190792, 0.42399915200254396, 0.84799830400508791},
     {1.4776010333066978, 0, 4.7766824456280297}, {0.29552020666133955, 0, 0.95533648912560598},
     {7.8069923647277727e-3, 7.9496847541265438e-3, 7.8033608761561815e-3}, {1.4540859255938862e-2, 1.6106251706628983e-2, 1.6720311965289114e-2}},
    {"concave bowl, x_o=(1,0,0.1), n_o tilted",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {-0.19518001458970663, 0.097590007294853315, 0.97590007294853309},
     {1, 0, 0.10000000000000001}, {-0.19611613513818402, 0, 0.98058067569092011},
     {1.4292413295010519e-2, 1.5219557303243956e-2, 1.565572449836781e-2}, {2.1307506069125402e-2, 2.3957143547440567e-2, 2.5517833151979351e-2}},
    {"slab 0.5 mm, x_o=(0.3,0,-0.5) on the far face, n_o=-z",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0, 0, 1},
     {0.29999999999999999, 0, -0.5}, {0, 0, -1},
     {7.562311882471604e-2, 7.7573367805015484e-2, 7.8396878616919674e-2}, {8.7531848045144815e-2, 9.3423209045705188e-2, 9.757565763977571e-2}},
    {"slab 0.5 mm, oblique light, x_o=(-0.2,0.4,-0.5)",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {-0.20000000000000001, 0.40000000000000002, -0.5}, {0, 0, -1},
     {5.2440641215655169e-2, 5.3747019393031337e-2, 5.4187383663369223e-2}, {6.4945882351782138e-2, 7.0326834033600523e-2, 7.4154838911519518e-2}},
    {"general 3D",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0.10000000000000001, -0.20000000000000001, 0.29999999999999999}, {0.097590007294853315, 0.19518001458970663, 0.97590007294853309}, {-0.54882129994845175, 0.32929277996907108, 0.76834981992783247},
     {0.90000000000000002, 0.5, 0.10000000000000001}, {0.28603877677367767, -0.095346258924559224, 0.95346258924559224},
     {1.3857519111786159e-2, 1.4597989591950161e-2, 1.486374251864118e-2}, {2.1138452807467977e-2, 2.3686429390294797e-2, 2.5137676994969185e-2}},
    {"skin-like eta 1.3, oblique",
     {0.73999999999999999, 0.88, 1.01}, {0.032000000000000001, 0.17000000000000001, 0.47999999999999998}, 1.3,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {0.80000000000000004, 0.29999999999999999, 0}, {0, 0, 1},
     {9.2524467004493381e-3, 7.4222319244247024e-3, 4.5754110078591673e-3}, {9.5558494412182941e-3, 7.4664540415570253e-3, 4.585882519040964e-3}},
    {"eta 1.0 (index matched), normal light, reference with eta<1 C2 fit",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1,
     {0, 0, 0}, {0, 0, 1}, {0, 0, 1},
     {1, 0, 0}, {0, 0, 1},
     {2.1672222919172087e-2, 2.0686456028707105e-2, 1.9406680676561055e-2}, {5.7658458595919129e-2, 6.7244124234462611e-2, 7.3410997756572052e-2}},
    {"eta 0.8, oblique 30deg (below critical), reference with eta<1 C2 fit",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 0.80000000000000004,
     {0, 0, 0}, {0, 0, 1}, {0.50000000000000011, 0, 0.86602540378443871},
     {1, 0, 0}, {0, 0, 1},
     {2.1622741264461528e-2, 2.1802595185133476e-2, 2.1279241852701527e-2}, {6.9478982964609516e-2, 8.1800719617382751e-2, 8.9740716605346239e-2}},
    {"slab 0.5 mm straight through (x_o - x_i parallel to n_i): n_i* := n_i",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0, 0, 1},
     {0, 0, -0.5}, {0, 0, -1},
     {1.2658425285774847e-1, 1.2948593878483302e-1, 1.3095007064898059e-1}, {1.3505964655280591e-1, 1.3998658957545143e-1, 1.4279101174855002e-1}},
    {"r = 0 (x_o == x_i), normal light: n_i* := n_i",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0, 0, 1},
     {0, 0, 0}, {0, 0, 1},
     {1.0879280533912567, 1.5585568868775092, 2.0460098207845044}, {1.0953354523396798, 1.5680486438078021, 2.0570768047549266}},
    {"r = 0 (x_o == x_i), oblique light: n_i* := n_i",
     {2.1899999999999999, 2.6200000000000001, 3}, {0.0020999999999999999, 0.0041000000000000003, 0.0071000000000000004}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {0, 0, 0}, {0, 0, 1},
     {1.3818965805222358, 1.9798098170173561, 2.5992070785166151}, {1.3895292637936028, 1.9896156721124036, 2.6106727180886216}},
    {"albedo' = 1 (sigma_a = 0), oblique",
     {2.1899999999999999, 1, 0.10000000000000001}, {0, 0, 0}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {1, 0, 0}, {0, 0, 1},
     {1.1578990987265607e-2, 7.6290320051068566e-3, 1.3013215881468491e-3}, {2.2123342366950431e-2, 9.9262604145259796e-3, 1.3247370677150095e-3}},
    {"albedo' -> 0 (sigma_s' = 1e-30 in the reference, 0 in C)",
     {0, 0, 0}, {0.5, 1, 2}, 1.5,
     {0, 0, 0}, {0, 0, 1}, {0.70710678118654746, 0, 0.70710678118654757},
     {1, 0, 0}, {0, 0, 1},
     {2.2601488546703719e-3, 1.2029298267203235e-3, 2.503960054410116e-4}, {2.2601488546703719e-3, 1.2029298267203235e-3, 2.503960054410116e-4}},
};

/* Same generator as dp_cases (50-digit mpmath evaluation of /work/ref/dirpole_ref.py's formula),
 * one band, light w_i = normalize(0.3, -0.2, 0.9) on the plane z = 0 at x_i = 0,
 * x_o = r (0.8, 0.6, 0); sigma_s' = 0 is evaluated in the reference as 1e-30; values below
 * 1e-300 (e^{-sigma_tr r} underflow) are written as 0. */
static const struct dp_grid_case dp_grid[] = {
    {0, 9.9999999999999995e-07, 0.001, 2.4056553205807541e-13, 2.4287387669667941e-13},
    {0, 9.9999999999999995e-07, 1, 2.4056343686901063e-13, 2.4287178150269773e-13},
    {0, 9.9999999999999995e-07, 30, 2.4050262664482366e-13, 2.4281097113576119e-13},
    {0, 0.001, 0.001, 2.4056343686901067e-7, 2.4287178150269776e-7},
    {0, 0.001, 1, 2.3848091039940004e-7, 2.4078925009719429e-7},
    {0, 0.001, 30, 1.8760632520326157e-7, 1.8991450508560757e-7},
    {0, 1, 0.001, 2.3848091039940003e-1, 2.4078925009719428e-1},
    {0, 1, 1, 9.4581243212239977e-3, 1.1742909533532596e-2},
    {0, 1, 30, 7.2904084754712581e-6, 5.5414695216779961e-4},
    {0, 1000, 0.001, 9.458124321223998e+3, 1.1742909533532597e+4},
    {0, 1000, 1, 2.0473203547153915e-4, 1.6877057090118296e+1},
    {0, 1000, 30, 7.5842142791092653e-9, 5.6261993728404831e-1},
    {9.9999999999999995e-07, 0, 0.001, 2.0709004476339752e-13, 2.0709004476339752e-13},
    {9.9999999999999995e-07, 0, 1, 2.0708805846180324e-13, 2.0708805846180324e-13},
    {9.9999999999999995e-07, 0, 30, 2.0703040884664797e-13, 2.0703040884664797e-13},
    {9.9999999999999995e-07, 9.9999999999999995e-07, 0.001, 8.8068878635778319e-13, 8.8068888935503873e-13},
    {9.9999999999999995e-07, 9.9999999999999995e-07, 1, 8.8067247644759905e-13, 8.8067257944486771e-13},
    {9.9999999999999995e-07, 9.9999999999999995e-07, 30, 8.8019919052972473e-13, 8.8019929352737433e-13},
    {9.9999999999999995e-07, 0.001, 0.001, 2.4093711833370611e-7, 2.4248099552462054e-7},
    {9.9999999999999995e-07, 0.001, 1, 2.3884847006420024e-7, 2.4039234257876198e-7},
    {9.9999999999999995e-07, 0.001, 30, 1.8783291390580844e-7, 1.8937663524920544e-7},
    {9.9999999999999995e-07, 1, 0.001, 2.3848126781884362e-1, 2.4076055335405556e-1},
    {9.9999999999999995e-07, 1, 1, 9.4580475190654681e-3, 1.1713780542187846e-2},
    {9.9999999999999995e-07, 1, 30, 7.2806500692137022e-6, 5.2567065780133494e-4},
    {9.9999999999999995e-07, 1000, 0.001, 9.4581242440788973e+3, 1.1741985158148319e+4},
    {9.9999999999999995e-07, 1000, 1, 2.0443588331379628e-4, 1.5977439941733085e+1},
    {9.9999999999999995e-07, 1000, 30, 3.8762855974974946e-9, 1.0879138184215983e-1},
    {0.001, 0, 0.001, 2.0708805846180326e-7, 2.0708805846180326e-7},
    {0.001, 0, 1, 2.0511408717792704e-7, 2.0511408717792704e-7},
    {0.001, 0, 30, 1.570915344689737e-7, 1.570915344689737e-7},
    {0.001, 9.9999999999999995e-07, 0.001, 2.0752592051612997e-7, 2.0752592051612997e-7},
    {0.001, 9.9999999999999995e-07, 1, 2.0554593211484244e-7, 2.0554593211484244e-7},
    {0.001, 9.9999999999999995e-07, 30, 1.5738484846209972e-7, 1.5738484846209972e-7},
    {0.001, 0.001, 0.001, 8.8067247644759917e-7, 8.8067257944486783e-7},
    {0.001, 0.001, 1, 8.6456149985475199e-7, 8.6456160286505549e-7},
    {0.001, 0.001, 30, 5.2881297332186662e-7, 5.2881307663150844e-7},
    {0.001, 1, 0.001, 2.3884847006420023e-1, 2.4039234257876197e-1},
    {0.001, 1, 1, 9.3911608158935872e-3, 1.0913004155507131e-2},
    {0.001, 1, 30, 3.6733208002856984e-6, 1.0453329115942762e-4},
    {0.001, 1000, 0.001, 9.4580475190654683e+3, 1.1713780542187846e+4},
    {0.001, 1000, 1, 9.8951126772746672e-5, 2.9854231880279107},
    {0.001, 1000, 30, 1.0894626143894537e-29, 1.5259442362750562e-23},
    {1, 0, 0.001, 2.0511408717792703e-1, 2.0511408717792703e-1},
    {1, 0, 1, 1.5927679430996538e-3, 1.5927679430996538e-3},
    {1, 0, 30, 3.9172011001487128e-27, 3.9172011001487128e-27},
    {1, 9.9999999999999995e-07, 0.001, 2.0511451879432576e-1, 2.0511451879432576e-1},
    {1, 9.9999999999999995e-07, 1, 1.592768807928495e-3, 1.592768807928495e-3},
    {1, 9.9999999999999995e-07, 30, 3.9190616917922161e-27, 3.9190616917922161e-27},
    {1, 0.001, 0.001, 2.0554593211484244e-1, 2.0554593211484244e-1},
    {1, 0.001, 1, 1.5936318161370825e-3, 1.5936318161370825e-3},
    {1, 0.001, 30, 4.7868839254114049e-27, 4.7868839254114049e-27},
    {1, 1, 0.001, 8.6456149985475195e-1, 8.6456160286505545e-1},
    {1, 1, 1, 1.6993882500137362e-3, 1.6994355564081391e-3},
    {1, 1, 30, 3.7041587723782377e-36, 8.7546259771938313e-36},
    {1, 1000, 0.001, 9.3911608158935875e+3, 1.0913004155507131e+4},
    {1, 1000, 1, 1.8067097759757206e-26, 2.6687662584971068e-23},
    {1, 1000, 30, 0, 0},
    {1000, 0, 0.001, 1.5927679430996539e+3, 1.5927679430996539e+3},
    {1000, 0, 1, 0, 0},
    {1000, 0, 30, 0, 0},
    {1000, 9.9999999999999995e-07, 0.001, 1.5927679439644837e+3, 1.5927679439644837e+3},
    {1000, 9.9999999999999995e-07, 1, 0, 0},
    {1000, 9.9999999999999995e-07, 30, 0, 0},
    {1000, 0.001, 0.001, 1.5927688079284951e+3, 1.5927688079284951e+3},
    {1000, 0.001, 1, 0, 0},
    {1000, 0.001, 30, 0, 0},
    {1000, 1, 0.001, 1.5936318161370826e+3, 1.5936318161370826e+3},
    {1000, 1, 1, 0, 0},
    {1000, 1, 30, 0, 0},
    {1000, 1000, 0.001, 1.6993882500137364e+3, 1.6994355564081392e+3},
    {1000, 1000, 1, 0, 0},
    {1000, 1000, 30, 0, 0},
};

static void sd_of(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no,
                  double out[3])
{
    lr_dirpole_sd(c, xi, ni, wi, xo, no, out);
}

/* The brief's values: marble, planar, normal incidence, x_o = (r, 0, 0); 1e-4 relative as
 * required. The same geometry is in dp_cases' source at 17 digits; here the printed 7. */
static void test_marble_required(void **state)
{
    (void)state;
    static const double r[3] = {0.5, 1.0, 2.0};
    static const double expect[3][3] = {{4.132487e-2, 4.553854e-2, 4.856541e-2},
                                        {1.481979e-2, 1.576677e-2, 1.620976e-2},
                                        {4.527690e-3, 4.400747e-3, 4.121464e-3}};
    lr_coeffs c = derive(&marble);
    for (int k = 0; k < 3; k++) {
        double out[3];
        sd_of(&c, O, Z, Z, lr_v3(r[k], 0.0, 0.0), Z, out);
        for (int j = 0; j < 3; j++)
            if (!(fabs(out[j] / expect[k][j] - 1.0) <= 1e-4))
                fail_msg("r %g band %d: %.7e, expected %.7e", r[k], j, out[j], expect[k][j]);
    }
}

static lr_medium case_medium(const struct dp_case *k)
{
    lr_medium m = {{k->sa[0], k->sa[1], k->sa[2]}, {k->ssp[0], k->ssp[1], k->ssp[2]}, k->eta, 0.0};
    return m;
}

/* Double-precision evaluation of S_d = real - virtual carries a few ulp of each source term,
 * plus the conditioning of the d'Eon & Irving 3C2 fit, which sums terms of size ~1600 to 0.46 at
 * eta 1.5 (C_E is good to ~4e-13 relative in double, in the reference as here). The difference
 * real - virtual amplifies that relative to S_d by scale / S_d. Observed: <= 2.1e-13 * scale;
 * asserted 1e-12 * scale, 8 orders below the 1e-4 the brief asks. */
static int close_to(double got, double want, double scale)
{
    return fabs(got - want) <= 1e-12 * scale + 1e-300;
}

/* Oblique light, grazing light, convex and concave surfaces, a thin slab seen from its far face
 * (the mu0 <= 0 branch of d_r), a general 3D configuration, eta 1.3, eta = 1 and 0.8, and the
 * hard cases r = 0, x_o straight through the slab, albedo' = 1 and albedo' -> 0, all against
 * the reference values generated from /work/ref/dirpole_ref.py. */
static void test_reference_cases(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof dp_cases / sizeof dp_cases[0]; k++) {
        const struct dp_case *t = &dp_cases[k];
        lr_medium m = case_medium(t);
        lr_coeffs c = derive(&m);
        double out[3];
        sd_of(&c, t->xi, t->ni, t->wi, t->xo, t->no, out);
        for (int j = 0; j < 3; j++)
            if (!close_to(out[j], t->sd[j], t->scale[j]))
                fail_msg("%s, band %d: %.17g, reference %.17g (scale %.3g)", t->name, j, out[j],
                         t->sd[j], t->scale[j]);
    }
}

/* Coefficients 1e-6..1e3 mm^-1 (and 0) at r = 1e-3, 1 and 30 mm against the 50-digit evaluation:
 * same tolerance; where the reference underflows (e^{-sigma_tr r} below 1e-300) the result
 * must be 0 or as small. */
static void test_coefficient_range(void **state)
{
    (void)state;
    lr_vec3 wi = lr_v3_normalize(lr_v3(0.3, -0.2, 0.9));
    for (size_t k = 0; k < sizeof dp_grid / sizeof dp_grid[0]; k++) {
        const struct dp_grid_case *g = &dp_grid[k];
        lr_medium m = {{g->sa, g->sa, g->sa}, {g->ssp, g->ssp, g->ssp}, 1.5, 0.0};
        lr_coeffs c = derive(&m);
        double out[3];
        sd_of(&c, O, Z, wi, lr_v3(0.8 * g->r, 0.6 * g->r, 0.0), Z, out);
        if (!(isfinite(out[0]) && out[0] >= 0.0 && close_to(out[0], g->sd, g->scale)))
            fail_msg("sigma_a %g sigma_s' %g r %g: %.17g, reference %.17g (scale %.3g)", g->sa,
                     g->ssp, g->r, out[0], g->sd, g->scale);
    }
}

/* Rotation by the unit quaternion q (Rodrigues form) then translation. */
static lr_vec3 rot(lr_vec3 v, const double q[4])
{
    lr_vec3 u = lr_v3(q[1], q[2], q[3]);
    double w = q[0];
    lr_vec3 t = lr_v3_scale(lr_v3_cross(u, v), 2.0);
    return lr_v3_add(lr_v3_add(v, lr_v3_scale(t, w)), lr_v3_cross(u, t));
}

/* S_d depends only on the relative configuration. Rotate every case about an arbitrary axis and
 * translate it by (123.4, -56.7, 8.9) mm: positions then carry absolute roundings of ~1.4e-14 mm,
 * a relative 5e-14 of the smallest nonzero r (0.3 mm); S_d's log-derivative in r is
 * sigma_tr + 3/r <= 10 mm^-1, giving <= 1e-12 relative on each source term; with the
 * cancellation factor scale / S_d <= 3 here: assert 1e-10 * scale. The r = 0 and straight-through
 * cases stay exactly degenerate (the fallback normal rotates with the scene). */
static void test_rigid_motion(void **state)
{
    (void)state;
    double q[4] = {0.78, 0.3, -0.5, 0.2};
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++)
        q[i] /= len;
    lr_vec3 tr = lr_v3(123.4, -56.7, 8.9);
    for (size_t k = 0; k < sizeof dp_cases / sizeof dp_cases[0]; k++) {
        const struct dp_case *t = &dp_cases[k];
        lr_medium m = case_medium(t);
        lr_coeffs c = derive(&m);
        double a[3], b[3];
        sd_of(&c, t->xi, t->ni, t->wi, t->xo, t->no, a);
        sd_of(&c, lr_v3_add(rot(t->xi, q), tr), rot(t->ni, q), rot(t->wi, q),
              lr_v3_add(rot(t->xo, q), tr), rot(t->no, q), b);
        for (int j = 0; j < 3; j++)
            if (!(fabs(a[j] - b[j]) <= 1e-10 * t->scale[j]))
                fail_msg("%s, band %d: %.17g before, %.17g after the motion", t->name, j, a[j], b[j]);
    }
}

/* mm -> m: lengths / 1000, coefficients * 1000. Every term of S'_d scales as 1/length^2 (D, de,
 * d_r, d_v scale with length; sigma_tr r is invariant), so S_d (mm^-2 sr^-1) must be 1e6 times
 * larger in m^-2. Inputs differ by roundings only: 1e-12 * scale, as above. */
static void test_unit_scaling(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof dp_cases / sizeof dp_cases[0]; k++) {
        const struct dp_case *t = &dp_cases[k];
        lr_medium m = case_medium(t), mm = m;
        for (int j = 0; j < 3; j++) {
            mm.sigma_a[j] *= 1000.0;
            mm.sigma_s_prime[j] *= 1000.0;
        }
        lr_coeffs c = derive(&m), cm = derive(&mm);
        double a[3], b[3];
        sd_of(&c, t->xi, t->ni, t->wi, t->xo, t->no, a);
        sd_of(&cm, lr_v3_scale(t->xi, 1e-3), t->ni, t->wi, lr_v3_scale(t->xo, 1e-3), t->no, b);
        for (int j = 0; j < 3; j++)
            if (!(fabs(b[j] * 1e-6 - a[j]) <= 1e-12 * t->scale[j]))
                fail_msg("%s, band %d: %.17g mm^-2, %.17g m^-2", t->name, j, a[j], b[j]);
    }
}

/* r -> 0 (planar, normal light): n_i* falls back to n_i at r = 0 exactly, which is also the limit
 * of n_i* in the plane, so S_d is continuous there. With the planar configuration S_d(r) =
 * S_d(0) + O(r / D) relative (D = 0.15 mm): at r = 1e-7 mm, <= 1e-5. The r = 0 value itself is in
 * dp_cases (1.088 mm^-2 sr^-1 red: finite). */
static void test_r_to_zero(void **state)
{
    (void)state;
    lr_coeffs c = derive(&marble);
    double a[3], b[3];
    sd_of(&c, O, Z, Z, O, Z, a);
    sd_of(&c, O, Z, Z, lr_v3(1e-7, 0.0, 0.0), Z, b);
    for (int j = 0; j < 3; j++) {
        assert_true(isfinite(a[j]) && a[j] > 0.0);
        assert_near_rel(b[j], a[j], 1e-5);
    }
}

/* albedo' -> 1 (sigma_a -> 0, sigma_tr -> 0): finite, and sigma_a = 1e-14 differs from 0 by
 * O(sigma_tr r) = O(sqrt(3e-14 * 2.19) * 1 mm) = 4e-7 relative: assert 1e-6.
 * albedo' -> 0 (sigma_s' -> 0, de -> Inf): sigma_s' = 0 gives de = Inf, which must not produce
 * NaN; the virtual source is gone and the real source's d_r tends to
 * sqrt(D mu0 (D mu0 + 2 |x x w_r|) + r^2). At sigma_s' = 1e-14 the virtual source sits at
 * 2 A de ~ 1e7 D, its term e^{-sigma_tr d_v} = 0, and q differs from the limit by O((r/de)^2):
 * assert 1e-9 relative. The limit's value is the dp_cases entry "albedo' -> 0".
 * Note the published S_d carries no albedo' factor: unlike R_d it does not vanish as
 * albedo' -> 0 (see dp_cases: 2.3e-3 mm^-2 sr^-1 for sigma_a = 0.5). */
static void test_albedo_limits(void **state)
{
    (void)state;
    lr_vec3 wi = lr_v3_normalize(lr_v3(1.0, 0.0, 1.0));
    lr_vec3 xo = lr_v3(1.0, 0.0, 0.0);
    double a[3], b[3];
    lr_medium m0 = {{0.0, 0.0, 0.0}, {2.19, 1.0, 0.1}, 1.5, 0.0}, m1 = m0;
    for (int j = 0; j < 3; j++)
        m1.sigma_a[j] = 1e-14;
    lr_coeffs c0 = derive(&m0), c1 = derive(&m1);
    assert_true(c0.sigma_tr[0] == 0.0);
    sd_of(&c0, O, Z, wi, xo, Z, a);
    sd_of(&c1, O, Z, wi, xo, Z, b);
    for (int j = 0; j < 3; j++) {
        assert_true(isfinite(a[j]) && a[j] > 0.0);
        assert_near_rel(b[j], a[j], 1e-6);
    }
    lr_medium n0 = {{0.5, 1.0, 2.0}, {0.0, 0.0, 0.0}, 1.5, 0.0}, n1 = n0;
    for (int j = 0; j < 3; j++)
        n1.sigma_s_prime[j] = 1e-14;
    c0 = derive(&n0);
    c1 = derive(&n1);
    assert_true(isinf(c0.de[0]));
    sd_of(&c0, O, Z, wi, xo, Z, a);
    sd_of(&c1, O, Z, wi, xo, Z, b);
    for (int j = 0; j < 3; j++) {
        assert_true(isfinite(a[j]) && a[j] > 0.0);
        assert_near_rel(b[j], a[j], 1e-9);
    }
    /* de = Inf at r = 0, straight through a slab and with the mu0 <= 0 branch: finite too. */
    sd_of(&c0, O, Z, wi, O, Z, a);
    sd_of(&c0, O, Z, Z, lr_v3(0.0, 0.0, -0.5), lr_v3(0.0, 0.0, -1.0), b);
    for (int j = 0; j < 3; j++)
        assert_true(isfinite(a[j]) && isfinite(b[j]) && a[j] >= 0.0 && b[j] >= 0.0);
}

/* eta = 1: F_t = 1, so sd_fresnel == sd exactly. eta = 0.8 (medium thinner than outside): light
 * entering beyond the critical angle (sin_i = 0.9 > 0.8) is totally reflected, so sd_fresnel = 0
 * exactly; S_d itself stays finite and takes the grazing refracted direction, the same for
 * every angle beyond critical in that plane (equal to 1e-12). Just inside (sin_i = 0.79)
 * sd_fresnel > 0 downstream of the refracted ray. */
static void test_eta_one_and_tir(void **state)
{
    (void)state;
    lr_vec3 xo = lr_v3(0.7, 0.2, 0.0), wi = lr_v3_normalize(lr_v3(0.4, -0.3, 0.8));
    lr_medium m = marble;
    m.eta = 1.0;
    lr_coeffs c = derive(&m);
    double a[3], b[3];
    lr_dirpole_sd(&c, O, Z, wi, xo, Z, a);
    lr_dirpole_sd_fresnel(&c, O, Z, wi, xo, Z, b);
    for (int j = 0; j < 3; j++)
        assert_true(a[j] == b[j] && a[j] > 0.0);

    m.eta = 0.8;
    c = derive(&m);
    double s1 = 0.9, s2 = 0.99;
    lr_vec3 w1 = lr_v3(s1, 0.0, sqrt(1.0 - s1 * s1)), w2 = lr_v3(s2, 0.0, sqrt(1.0 - s2 * s2));
    lr_dirpole_sd_fresnel(&c, O, Z, w1, xo, Z, a);
    for (int j = 0; j < 3; j++)
        assert_true(a[j] == 0.0);
    lr_dirpole_sd(&c, O, Z, w1, xo, Z, a);
    lr_dirpole_sd(&c, O, Z, w2, xo, Z, b);
    for (int j = 0; j < 3; j++) {
        assert_true(isfinite(a[j]) && a[j] >= 0.0);
        assert_near(a[j], b[j], 1e-12 * (a[j] + b[j]) + 1e-300);
    }
    /* Downstream of the (nearly tangential) refracted ray; upstream, at xo, the model's virtual
     * source outweighs the real one in the red band and S_d clamps to 0, as the reference does. */
    double s3 = 0.79;
    lr_dirpole_sd_fresnel(&c, O, Z, lr_v3(s3, 0.0, sqrt(1.0 - s3 * s3)), lr_v3(-0.7, 0.2, 0.0), Z, a);
    for (int j = 0; j < 3; j++)
        assert_true(isfinite(a[j]) && a[j] > 0.0);
}

/* Grazing light (cos_i = 1e-9, eta 1.5): sd_fresnel = S_d F_t with F_t -> 0 linearly,
 * F_t ~ 2 cos_i (1 + eta^2) / (eta cos_t0) = 5.8e-9 (test_optics_fresnel); the product is that
 * factor times a finite S_d. Light from behind the surface gives exactly 0. */
static void test_grazing_and_behind(void **state)
{
    (void)state;
    lr_coeffs c = derive(&marble);
    double ci = 1e-9;
    lr_vec3 wi = lr_v3(sqrt(1.0 - ci * ci), 0.0, ci), xo = lr_v3(1.0, 0.5, 0.0);
    double a[3], b[3];
    lr_dirpole_sd(&c, O, Z, wi, xo, Z, a);
    lr_dirpole_sd_fresnel(&c, O, Z, wi, xo, Z, b);
    double ft = lr_fresnel_transmittance(ci, 1.5);
    assert_true(ft > 0.0 && ft < 1e-8);
    for (int j = 0; j < 3; j++) {
        assert_true(isfinite(a[j]) && a[j] > 0.0);
        assert_near(b[j], a[j] * ft, 1e-15 * a[j] * ft);
    }
    lr_dirpole_sd_fresnel(&c, O, Z, lr_v3_normalize(lr_v3(0.3, 0.0, -0.95)), xo, Z, b);
    for (int j = 0; j < 3; j++)
        assert_true(b[j] == 0.0);
}

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform01(uint64_t *s) { return (double)(splitmix64(s) >> 11) * 0x1.0p-53; }

static lr_vec3 random_dir(uint64_t *s)
{
    double z = 1.0 - 2.0 * uniform01(s), phi = 2.0 * M_PI * uniform01(s);
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    return lr_v3(r * cos(phi), r * sin(phi), z);
}

/* The property the header promises: finite and >= 0 for every finite input, and
 * sd_fresnel <= sd (F_t <= 1). Materials: every sigma_a, sigma_s' pair from {0, 1e-6, 1e-3, 1,
 * 1e3} mm^-1 (not both 0) at eta 0.5, 0.8, 1, 1.5, 2.5; geometries (fixed seed): random normals
 * and light directions (a quarter from behind), distances 1e-6..1e2 mm, with x_o == x_i and
 * x_o - x_i parallel to n_i mixed in. 24 x 5 x 300 configurations. */
static void test_finite_everywhere(void **state)
{
    (void)state;
    const double v[] = {0.0, 1e-6, 1e-3, 1.0, 1e3};
    const double etas[] = {0.5, 0.8, 1.0, 1.5, 2.5};
    uint64_t seed = 20140101;
    for (int a = 0; a < 5; a++)
        for (int s = 0; s < 5; s++)
            for (int h = 0; h < 5; h++) {
                if (v[a] == 0.0 && v[s] == 0.0)
                    continue;
                lr_medium m = {{v[a], v[a], v[a]}, {v[s], v[s], v[s]}, etas[h], 0.0};
                lr_coeffs c = derive(&m);
                for (int k = 0; k < 300; k++) {
                    lr_vec3 xi = lr_v3(uniform01(&seed) - 0.5, uniform01(&seed), 0.0);
                    lr_vec3 ni = random_dir(&seed), wi = random_dir(&seed), no = random_dir(&seed);
                    if (lr_v3_dot(wi, ni) < 0.0 && (k & 3))
                        wi = lr_v3_scale(wi, -1.0);
                    double r = pow(10.0, -6.0 + 8.0 * uniform01(&seed));
                    lr_vec3 dir = k % 7 == 0 ? lr_v3_scale(ni, -1.0) : random_dir(&seed);
                    lr_vec3 xo = k % 11 == 0 ? xi : lr_v3_add(xi, lr_v3_scale(dir, r));
                    double out[3], outf[3];
                    lr_dirpole_sd(&c, xi, ni, wi, xo, no, out);
                    lr_dirpole_sd_fresnel(&c, xi, ni, wi, xo, no, outf);
                    for (int j = 0; j < 3; j++)
                        if (!(isfinite(out[j]) && out[j] >= 0.0 && outf[j] >= 0.0 &&
                              outf[j] <= out[j]))
                            fail_msg("sigma_a %g sigma_s' %g eta %g k %d: sd %g, sd_fresnel %g",
                                     v[a], v[s], etas[h], k, out[j], outf[j]);
                }
            }
}

static void expect_geometry_rejected(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi,
                                     lr_vec3 xo, lr_vec3 no, const char *field)
{
    lr_err e;
    double out[3] = {-1.0, -1.0, -1.0};
    lr_err_clear(&e);
    assert_int_equal(lr_dirpole_sd_checked(c, xi, ni, wi, xo, no, 0, out, &e), LR_EINVAL);
    if (!strstr(e.msg, field))
        fail_msg("message '%s' does not name '%s'", e.msg, field);
    assert_true(out[0] == -1.0);
}

/* Checked entry point: non-finite positions, non-finite or zero-length directions rejected with
 * the field named; directions of any nonzero length are normalised, so the result equals the
 * unit-vector evaluation (to the rounding of the normalisation, 1e-15 relative * scale). */
static void test_checked(void **state)
{
    (void)state;
    lr_coeffs c = derive(&marble);
    lr_vec3 xo = lr_v3(1.0, 0.0, 0.0), nan3 = lr_v3(NAN, 0.0, 0.0), inf3 = lr_v3(0.0, INFINITY, 0.0);
    expect_geometry_rejected(&c, nan3, Z, Z, xo, Z, "x_i");
    expect_geometry_rejected(&c, O, Z, Z, inf3, Z, "x_o");
    expect_geometry_rejected(&c, O, O, Z, xo, Z, "n_i");
    expect_geometry_rejected(&c, O, Z, nan3, xo, Z, "w_i");
    expect_geometry_rejected(&c, O, Z, Z, xo, lr_v3(0.0, 0.0, 1e-200), "n_o");
    expect_geometry_rejected(&c, O, Z, Z, xo, inf3, "n_o");
    lr_err e;
    assert_int_equal(lr_dirpole_sd_checked(NULL, O, Z, Z, xo, Z, 0, (double[3]){0}, &e), LR_EINVAL);

    lr_vec3 wi = lr_v3_normalize(lr_v3(0.3, 0.1, 0.9));
    double a[3], b[3], f[3], g[3];
    lr_dirpole_sd(&c, O, Z, wi, xo, Z, a);
    lr_dirpole_sd_fresnel(&c, O, Z, wi, xo, Z, f);
    assert_int_equal(lr_dirpole_sd_checked(&c, O, lr_v3_scale(Z, 2.5), lr_v3_scale(wi, 7.0), xo,
                                           lr_v3_scale(Z, 0.01), 0, b, &e), LR_OK);
    assert_int_equal(lr_dirpole_sd_checked(&c, O, Z, wi, xo, Z, 1, g, &e), LR_OK);
    for (int j = 0; j < 3; j++) {
        assert_near(a[j], b[j], 1e-14 * a[j]);
        assert_near(f[j], g[j], 1e-14 * f[j]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_marble_required),
        cmocka_unit_test(test_reference_cases),
        cmocka_unit_test(test_coefficient_range),
        cmocka_unit_test(test_rigid_motion),
        cmocka_unit_test(test_unit_scaling),
        cmocka_unit_test(test_r_to_zero),
        cmocka_unit_test(test_albedo_limits),
        cmocka_unit_test(test_eta_one_and_tir),
        cmocka_unit_test(test_grazing_and_behind),
        cmocka_unit_test(test_finite_everywhere),
        cmocka_unit_test(test_checked),
    };
    return cmocka_run_group_tests_name("optics_dirpole", tests, NULL, NULL);
}
