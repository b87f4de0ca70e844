#ifndef LR_BASE_MEDIAN_H
#define LR_BASE_MEDIAN_H

/* The median of the finite values of v[0..n): timings and errors where a failed measurement is
 * stored as NaN or Inf. NaN when no value is finite (or out of memory). v is not changed. */
double lr_median_finite(const double *v, int n);

#endif
