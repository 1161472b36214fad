# RBF core (issue 3): fit by projected Cholesky, solve, blocked OpenMP evaluation.
list(APPEND CM_CORE_SOURCES rbf.c rbf_merge.c rbf_sum.c)
# The kernel loops need contraction into FMA and sqrt without errno to vectorise; the
# results do not depend on errno. Kept to the RBF sources, not global.
set_source_files_properties(rbf_sum.c PROPERTIES COMPILE_OPTIONS "-O3;-fno-math-errno;-ffp-contract=fast")
