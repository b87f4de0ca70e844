/* Spherical harmonics l <= 2: orthonormality by exact quadrature, the published constants, and
 * irradiance against direct integration of the clamped cosine and against Ramamoorthi &
 * Hanrahan's matrix form (seed 002 Eq. 10-11). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/support/near.h"
#include <math.h>

#include "render/optics/optics.h"
#include "tests/support/quadrature.h"

#define NZ 16   /* Gauss-Legendre points in z = cos(theta) */
#define NPHI 32 /* equally spaced azimuths */

/* Y_i Y_j is a polynomial of degree <= 4 in (x, y, z). Integrated over phi with NPHI equal steps
 * it is exact for trigonometric degree < NPHI; what survives is a polynomial of degree <= 4 in z
 * (odd powers of sin(theta) come with odd trig powers, which integrate to 0), integrated exactly
 * by NZ >= 3 Gauss-Legendre points. So the quadrature is exact up to roundings: 1e-14. */
static void test_orthonormal(void **state)
{
    (void)state;
    double zx[NZ], zw[NZ], gram[9][9] = {{0}};
    lrt_gauss_legendre(NZ, zx, zw);
    for (int a = 0; a < NZ; a++)
        for (int b = 0; b < NPHI; b++) {
            double z = zx[a], s = sqrt(1.0 - z * z), phi = 2.0 * M_PI * b / NPHI;
            double y[9], w = zw[a] * 2.0 * M_PI / NPHI;
            lr_sh9_basis(lr_v3(s * cos(phi), s * sin(phi), z), y);
            for (int i = 0; i < 9; i++)
                for (int j = 0; j < 9; j++)
                    gram[i][j] += w * y[i] * y[j];
        }
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 9; j++)
            if (!(fabs(gram[i][j] - (i == j)) <= 1e-14))
                fail_msg("<Y_%d, Y_%d> = %.17g", i, j, gram[i][j]);
}

/* Ramamoorthi & Hanrahan 2001's printed constants (6 digits): 0.282095, 0.488603 (x, y, z),
 * 1.092548 (xy, yz, xz), 0.315392 (3z^2 - 1), 0.546274 (x^2 - y^2). Tolerance 5e-7 = half the
 * last printed digit (times the monomial, <= 1, at the direction used). */
static void test_published_constants(void **state)
{
    (void)state;
    lr_vec3 d = lr_v3_normalize(lr_v3(0.3, -0.5, 0.8));
    double y[9];
    lr_sh9_basis(d, y);
    double x = d.x, yy = d.y, z = d.z;
    const double expect[9] = {0.282095,           0.488603 * yy,     0.488603 * z,
                              0.488603 * x,       1.092548 * x * yy, 1.092548 * yy * z,
                              0.315392 * (3.0 * z * z - 1.0), 1.092548 * x * z,
                              0.546274 * (x * x - yy * yy)};
    for (int i = 0; i < 9; i++)
        assert_near(y[i], expect[i], 5e-7);
}

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform_pm1(uint64_t *s) { return 2.0 * (double)(splitmix64(s) >> 11) * 0x1.0p-53 - 1.0; }

/* E(n) = integral L(w) max(0, n.w) dw by quadrature over the hemisphere around n: in a frame
 * (t, b, n), mu = n.w in [0, 1] by Gauss-Legendre and phi by equal steps. L is a polynomial of
 * degree <= 2, so L mu has degree <= 3 in the frame coordinates; as above this is integrated
 * exactly by 8 x 16 points (no kink: the clamp is the integration boundary). */
static double irradiance_quadrature(const double L[9], lr_vec3 n)
{
    lr_vec3 a = fabs(n.x) < 0.9 ? lr_v3(1.0, 0.0, 0.0) : lr_v3(0.0, 1.0, 0.0);
    lr_vec3 t = lr_v3_normalize(lr_v3_cross(a, n)), b = lr_v3_cross(n, t);
    double mx[8], mw[8], sum = 0.0;
    lrt_gauss_legendre(8, mx, mw);
    for (int i = 0; i < 8; i++)
        for (int k = 0; k < 16; k++) {
            double mu = 0.5 * (mx[i] + 1.0), w = 0.5 * mw[i] * 2.0 * M_PI / 16.0;
            double s = sqrt(1.0 - mu * mu), phi = 2.0 * M_PI * k / 16.0;
            lr_vec3 dir = lr_v3_add(lr_v3_add(lr_v3_scale(t, s * cos(phi)), lr_v3_scale(b, s * sin(phi))),
                                    lr_v3_scale(n, mu));
            double y[9], radiance = 0.0;
            lr_sh9_basis(dir, y);
            for (int m = 0; m < 9; m++)
                radiance += L[m] * y[m];
            sum += w * radiance * mu;
        }
    return sum;
}

/* Irradiance of random radiance fields band-limited to l <= 2 (fixed seed) at the poles, the
 * axes and random normals, against the exact quadrature: 1e-13 * sum |L_lm| (roundings of ~150
 * terms). Also a published anchor: uniform radiance L gives E = pi L. */
static void test_irradiance_vs_quadrature(void **state)
{
    (void)state;
    uint64_t seed = 2001;
    for (int f = 0; f < 20; f++) {
        double L[9], norm1 = 0.0;
        for (int m = 0; m < 9; m++) {
            L[m] = uniform_pm1(&seed);
            norm1 += fabs(L[m]);
        }
        lr_vec3 normals[10] = {lr_v3(0, 0, 1), lr_v3(0, 0, -1), lr_v3(1, 0, 0), lr_v3(0, -1, 0)};
        for (int k = 4; k < 10; k++)
            normals[k] = lr_v3_normalize(lr_v3(uniform_pm1(&seed), uniform_pm1(&seed), uniform_pm1(&seed)));
        for (int k = 0; k < 10; k++) {
            double e = lr_sh9_irradiance(L, normals[k]), q = irradiance_quadrature(L, normals[k]);
            if (!(fabs(e - q) <= 1e-13 * norm1))
                fail_msg("field %d normal %d: SH %.17g, quadrature %.17g", f, k, e, q);
        }
    }
    double uniform[9] = {2.0 * sqrt(M_PI)}; /* L(w) = L_00 Y_00 = 1 everywhere */
    double e = lr_sh9_irradiance(uniform, lr_v3(0.6, 0.0, 0.8));
    assert_near(e, M_PI, 1e-15);
}

/* Seed 002 Eq. 10-11 (after Ramamoorthi & Hanrahan 2001): E(n) = n^T M n with n = (x, y, z, 1)
 * and c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708. The seed's
 * printed M has two transcription slips in its last row (c1 L11 and c2 L2-1 where R&H have
 * c2 L11 and c2 L1-1); M must be symmetric, so the row mirrors the last column. Each constant is
 * rounded to 5e-7 and enters with |monomial| <= 1, at most twice: |dE| <= 1e-6 sum |L|. */
static void test_irradiance_matrix_form(void **state)
{
    (void)state;
    const double c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
    uint64_t seed = 12;
    for (int f = 0; f < 50; f++) {
        double L[9], norm1 = 0.0;
        for (int m = 0; m < 9; m++) {
            L[m] = uniform_pm1(&seed);
            norm1 += fabs(L[m]);
        }
        /* L index: 0 L00, 1 L1-1, 2 L10, 3 L11, 4 L2-2, 5 L2-1, 6 L20, 7 L21, 8 L22 */
        double M[4][4] = {{c1 * L[8], c1 * L[4], c1 * L[7], c2 * L[3]},
                          {c1 * L[4], -c1 * L[8], c1 * L[5], c2 * L[1]},
                          {c1 * L[7], c1 * L[5], c3 * L[6], c2 * L[2]},
                          {c2 * L[3], c2 * L[1], c2 * L[2], c4 * L[0] - c5 * L[6]}};
        lr_vec3 n = lr_v3_normalize(lr_v3(uniform_pm1(&seed), uniform_pm1(&seed), uniform_pm1(&seed)));
        double v[4] = {n.x, n.y, n.z, 1.0}, e = 0.0;
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++)
                e += v[i] * M[i][j] * v[j];
        assert_near(lr_sh9_irradiance(L, n), e, 1e-6 * norm1);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_orthonormal),
        cmocka_unit_test(test_published_constants),
        cmocka_unit_test(test_irradiance_vs_quadrature),
        cmocka_unit_test(test_irradiance_matrix_form),
    };
    return cmocka_run_group_tests_name("optics_sh", tests, NULL, NULL);
}
