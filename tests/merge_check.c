/* merge_check A.exr B.exr: whether two renders of as many samples (a merged reference and one
 * render, say) agree within their noise (merge_stats.h); exit 0 when they do, 1 when not, 2 when
 * they cannot be compared. For test_slurm.sh. */
#include <stdio.h>

#include "merge_stats.h"

int main(int argc, char **argv) {
    if (argc != 3) return fprintf(stderr, "usage: merge_check A.exr B.exr\n"), 2;
    merge_stats st;
    if (merge_stats_compare(argv[1], argv[2], &st) != 0) return 2;
    printf("merge_check: %.3f of |z| below 0.674 over %zu pixel channels; relative L2 %.4g, noise predicts %.4g "
           "(%.4g and %.4g)\n",
           st.below, st.compared, st.measured, st.predicted, st.noise_a, st.noise_b);
    return merge_stats_agree(&st) ? 0 : 1;
}
