/* lamprig tests — numerical quadrature used to check closed forms and fits independently. */
#ifndef LRT_QUADRATURE_H
#define LRT_QUADRATURE_H

typedef double (*lrt_fn)(double x, void *ctx);

/* Nodes x[k] and weights w[k] of the n-point Gauss-Legendre rule on [-1, 1] (n <= 64), found
 * by Newton's method on P_n; exact for polynomials of degree <= 2n - 1. */
void lrt_gauss_legendre(int n, double *x, double *w);

/* Composite Gauss-Legendre: `panels` equal panels on [a, b], n points each. */
double lrt_gl_integrate(lrt_fn f, void *ctx, double a, double b, int n, int panels);

/* Adaptive Simpson on [a, b] to absolute tolerance tol (Richardson-corrected; recursion depth
 * limited to 50). */
double lrt_simpson(lrt_fn f, void *ctx, double a, double b, double tol);

#endif
