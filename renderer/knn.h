/* glint — k-nearest-neighbour distances over a point set (the VSL radius rule): a k-d tree built
 * once, one bounded query per point. */
#ifndef GLINT_KNN_H
#define GLINT_KNN_H

#include <stddef.h>

#include "gmath.h"

/* For each of the n points (point i at (const char *)points + i * stride, so an array of structs
 * with a vec3 member works) writes to out[i] the distance to its k-th nearest other point;
 * duplicates count, at distance 0. With fewer than k others, the farthest one; a lone point gets
 * 0. Non-finite points get INFINITY and are nobody's neighbour. Returns 0, or -1 when out of
 * memory. */
int knn_distances(const vec3 *points, size_t stride, int n, int k, float *out);

#endif
