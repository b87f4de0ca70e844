#include "tests/support/quadrature.h"

#include <math.h>

void lrt_gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < (n + 1) / 2; i++) {
        /* Tricomi's initial guess for the i-th root, then Newton on P_n. */
        double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        w[i] = w[n - 1 - i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
}

double lrt_gl_integrate(lrt_fn f, void *ctx, double a, double b, int n, int panels)
{
    double x[64], w[64];
    lrt_gauss_legendre(n, x, w);
    double h = (b - a) / panels, sum = 0.0;
    for (int p = 0; p < panels; p++) {
        double lo = a + p * h, mid = lo + 0.5 * h;
        for (int k = 0; k < n; k++)
            sum += 0.5 * h * w[k] * f(mid + 0.5 * h * x[k], ctx);
    }
    return sum;
}

static double simpson_rec(lrt_fn f, void *ctx, double a, double b, double fa, double fm, double fb,
                          double whole, double tol, int depth)
{
    double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    double flm = f(lm, ctx), frm = f(rm, ctx);
    double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    double delta = left + right - whole;
    if (depth <= 0 || fabs(delta) <= 15.0 * tol)
        return left + right + delta / 15.0;
    return simpson_rec(f, ctx, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
           simpson_rec(f, ctx, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}

double lrt_simpson(lrt_fn f, void *ctx, double a, double b, double tol)
{
    /* Start from 8 panels so that a narrow feature cannot hide between the first 3 samples. */
    double sum = 0.0, h = (b - a) / 8.0;
    for (int p = 0; p < 8; p++) {
        double lo = a + p * h, hi = lo + h, mid = 0.5 * (lo + hi);
        double flo = f(lo, ctx), fmid = f(mid, ctx), fhi = f(hi, ctx);
        double whole = h / 6.0 * (flo + 4.0 * fmid + fhi);
        sum += simpson_rec(f, ctx, lo, hi, flo, fmid, fhi, whole, tol / 8.0, 50);
    }
    return sum;
}
