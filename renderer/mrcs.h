/* glint — matrix row-column sampling (Hasan, Pellacini, Bala, SIGGRAPH 2007): clusters the columns
 * (virtual lights) of the reduced light transport matrix, R sampled rows (pixels) by N columns,
 * and picks one representative column per cluster, so every pixel can be shaded from the
 * representatives only.
 *
 * Distance between columns i and j (rho = a column of the reduced matrix, |.| its 2-norm):
 *     d(i, j) = |rho_i| |rho_j| | rho_i/|rho_i| - rho_j/|rho_j| |^2 = 2 (|rho_i| |rho_j| - rho_i . rho_j).
 * Cost of a cluster K, summed over its unordered pairs {i, j}, i != j:
 *     cost(K) = sum_{i<j} 2 (|rho_i| |rho_j| - rho_i . rho_j)
 *             = [(sum |rho_i|)^2 - sum |rho_i|^2] - [|sum rho_i|^2 - sum |rho_i|^2]
 *             = (sum_K |rho_i|)^2 - |sum_K rho_i|^2,
 * constant 1 for unordered pairs (the paper's sum over ordered pairs is twice this). It costs
 * O(|K| R) and is 0 exactly when all members point the same way.
 *
 * Unbiasedness: a cluster's representative j is drawn with probability |rho_j| / W (W = the sum of
 * its members' norms) and scaled by W / |rho_j|, so the expected contribution of the cluster to
 * any pixel is the sum of its members' contributions, whatever the clustering. Columns that are
 * zero in every sampled row are dropped: they are assumed to light nothing. */
#ifndef GLINT_MRCS_H
#define GLINT_MRCS_H

#include "rng.h"

typedef struct {
    int representative; /* column index */
    float scale;        /* multiply the representative's contribution by this: cluster norm sum / representative norm */
    float weight;       /* the cluster's total norm (sum of its columns' norms), for sampling clusters per pixel */
    int size;           /* columns in the cluster */
} mrcs_cluster;

/* Clusters the N columns of the R x N reduced matrix (row-major: value of column j in row i at
 * m[i * n + j], all finite and >= 0) into at most C clusters. Columns with zero norm are left out
 * (they light no sampled row). Returns the number of clusters written to out (<= C), or -1 when
 * out of memory. With C >= the number of non-zero columns every non-zero column is its own
 * cluster with scale 1.
 *
 * Otherwise, as in the paper: (a) sampling clustering: about 2C/3 distinct columns drawn with
 * probability proportional to their norms become centres, and every non-zero column joins the
 * centre nearest in d (a centre with 1 - cos below 1e-4 counts as distance 0 and ties go to the
 * earlier centre, so columns of one direction, rounding apart, always stay together);
 * (b) top-down splitting: the cluster of highest cost is split until there are C clusters or no
 * cluster has two members. A split projects the members' directions onto the line through two
 * far-apart members and cuts the sorted projections where the two halves' costs sum lowest
 * (prefix sums); among cuts within rounding noise of the best (1e-10 (sum of norms)^2: members
 * all alike) it takes the one that halves the norm sum most evenly. Halves are never empty.
 * Norms and costs are accumulated in double, so norms from 1e-30 to 1e30 mix without overflow;
 * weight and scale are clamped to FLT_MAX (an event of probability below 2^-53 for scale).
 * m is not modified; rng draws the centres, the split lines and the representatives. C < 1, n < 1
 * or rows < 1 write nothing and return 0. */
int mrcs_cluster_columns(const float *m, int rows, int n, int C, rng_state *rng, mrcs_cluster *out);

#endif
