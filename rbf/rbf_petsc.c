/* The iterative r^3 solver distributed over MPI ranks through PETSc (issue 10, section 3):
 * KSPFGMRES on a MatShell whose rows are split over the ranks, the two-level restricted
 * Schwarz preconditioner of rbf_schwarz.c as a PCSHELL, the polynomial block handled in its
 * null space as in rbf_iterative.c.
 *
 * The mathematics is the serial solver's, step for step, so that both take the same
 * iterations and agree to round-off: the operator is Pi A on range(Pi) (Pi = I - Q1 Q1'),
 * the preconditioner Pi M, classical Gram-Schmidt with one refinement, and the restarts are
 * ours: each restart cycle is one KSPSolve (at most `restart` iterations, so PETSc never
 * restarts by itself) on the true projected residual, stopped by our test on FGMRES's
 * 2-norm estimate against the max-norm target, exactly as solve_group does it.
 *
 * Distribution: every rank holds all centres (3 m doubles: replicated data is cheap beside
 * m^2 kernel pairs) and owns a block of rows; a matvec gathers x to all ranks and each sums
 * its rows, so the O(m^2) work is divided by the ranks. The preconditioner is replicated
 * (each rank applies all of it and keeps its rows): at m <= 10^5 it costs a few per cent of
 * a matvec. For many nodes the design is to number the rows by Schwarz leaves so that each
 * rank owns whole subdomains (local solves without communication, the coarse solve
 * replicated) and to replace the gather by a treecode's far field; see README. */
#include "rbf_internal.h"

#include <float.h>
#include <math.h>
#include <petscksp.h>
#include <stdlib.h>
#include <string.h>

struct cm_rbf_petsc {
    const cm_rbf *r;
    int threads;
    PetscInt lo, hi;   /* rows of this rank */
    Mat A;             /* MatShell: Pi A */
    KSP ksp;
    Vec q1[4];         /* distributed columns of Q1 */
    Vec all;           /* sequential copy of a whole vector on every rank */
    VecScatter to_all;
    double *full_out;  /* m: the preconditioner's full output */
    double target;     /* the running cycle's stopping target on the 2-norm estimate */
    int matvecs;       /* products with A since the solve began */
};

static int g_initialised_here; /* we called PetscInitialize, so we finalise */

int cm_rbf_petsc_available(void) { return 1; }

static cm_status petsc_fail(cm_context *ctx, PetscErrorCode e, const char *what)
{
    const char *text = NULL;
    PetscErrorMessage((int)e, &text, NULL);
    return cm_error(ctx, e == PETSC_ERR_MEM ? CM_ERR_NOMEM : CM_ERR_INTERNAL,
                    "cm_rbf (PETSc): %s failed: %s (PETSc error %d)", what,
                    text ? text : "unknown error", (int)e);
}

#define P(call)                                          \
    do {                                                 \
        PetscErrorCode e_ = (call);                      \
        if (e_) {                                        \
            st = petsc_fail(ctx, e_, #call);             \
            goto done;                                   \
        }                                                \
    } while (0)

cm_status cm_rbf_petsc_initialize(cm_context *ctx)
{
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up) return CM_OK;
    cm_status st = CM_OK;
    /* the program's signal handlers stay (they remove temporary outputs); PETSc's errors
     * come back as codes, not as printed tracebacks: the library never prints */
    P(PetscOptionsSetValue(NULL, "-no_signal_handler", NULL));
    P(PetscInitializeNoArguments());
    g_initialised_here = 1;
    P(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
done:
    return st;
}

void cm_rbf_petsc_rank(int *rank, int *size)
{
    int rk = 0, sz = 1;
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up) {
        MPI_Comm_rank(PETSC_COMM_WORLD, &rk);
        MPI_Comm_size(PETSC_COMM_WORLD, &sz);
    }
    if (rank) *rank = rk;
    if (size) *size = sz;
}

void cm_rbf_petsc_finalize(void)
{
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up && g_initialised_here) PetscFinalize();
    g_initialised_here = 0;
}

/* v -= Q1 (Q1' v), twice, as project() in rbf_iterative.c. */
static PetscErrorCode project(cm_rbf_petsc *ps, Vec v)
{
    const int k = ps->r->k;
    PetscScalar s[4];
    for (int pass = 0; pass < 2; ++pass) {
        PetscCall(VecMDot(v, k, ps->q1, s));
        for (int a = 0; a < k; ++a) s[a] = -s[a];
        PetscCall(VecMAXPY(v, k, s, ps->q1));
    }
    return 0;
}

/* Gathers x (distributed) into ps->all on every rank; *xa points at it. */
static PetscErrorCode gather(cm_rbf_petsc *ps, Vec x, const PetscScalar **xa)
{
    PetscCall(VecScatterBegin(ps->to_all, x, ps->all, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(ps->to_all, x, ps->all, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGetArrayRead(ps->all, xa));
    return 0;
}

/* y = A x on this rank's rows (compensated sums, as the serial matvec: the same rows come
 * out bit for bit); plain: ordinary sums (the floor estimate); then Pi if proj. */
static PetscErrorCode apply_a(cm_rbf_petsc *ps, Vec x, Vec y, int proj, int plain)
{
    const cm_rbf *r = ps->r;
    const PetscScalar *xa;
    PetscScalar *ya;
    PetscCall(gather(ps, x, &xa));
    PetscCall(VecGetArray(y, &ya));
    const size_t n = (size_t)(ps->hi - ps->lo);
    if (plain)
        cm_rbf_kernel_sum(r->kernel, 3, r->m, r->c, xa, 1, n, r->c + ps->lo, r->m, ya, 1,
                          ps->threads);
    else
        cm_rbf_kernel_sum_acc(r->m, r->c, xa, 1, n, r->c + ps->lo, r->m, ya, 1, ps->threads);
    PetscCall(VecRestoreArray(y, &ya));
    PetscCall(VecRestoreArrayRead(ps->all, &xa));
    if (!plain) ++ps->matvecs; /* the floor estimate's plain sum is not counted, as serially */
    if (proj) PetscCall(project(ps, y));
    return 0;
}

static PetscErrorCode shell_mult(Mat A, Vec x, Vec y)
{
    cm_rbf_petsc *ps;
    PetscCall(MatShellGetContext(A, &ps));
    return apply_a(ps, x, y, 1, 0);
}

/* y = Pi M x: the whole preconditioner on every rank, each keeps its rows. */
static PetscErrorCode shell_pc(PC pc, Vec x, Vec y)
{
    cm_rbf_petsc *ps;
    PetscCall(PCShellGetContext(pc, &ps));
    const PetscScalar *xa;
    PetscScalar *ya;
    PetscCall(gather(ps, x, &xa));
    cm_rbf_schwarz_apply(cm_rbf_iterative_pc(ps->r), ps->r, 1, xa, ps->full_out, ps->threads);
    PetscCall(VecRestoreArrayRead(ps->all, &xa));
    PetscCall(VecGetArray(y, &ya));
    memcpy(ya, ps->full_out + ps->lo, (size_t)(ps->hi - ps->lo) * sizeof *ya);
    PetscCall(VecRestoreArray(y, &ya));
    return project(ps, y);
}

/* The serial inner loop's stop: FGMRES's residual estimate below the cycle's target (the
 * iteration limit is KSP's own max_it, set per cycle). */
static PetscErrorCode converged(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason *reason,
                                void *vps)
{
    (void)ksp;
    const cm_rbf_petsc *ps = vps;
    *reason = it > 0 && rnorm <= ps->target ? KSP_CONVERGED_ATOL : KSP_CONVERGED_ITERATING;
    return 0;
}

void cm_rbf_petsc_destroy(cm_rbf_petsc **pp)
{
    if (!pp || !*pp) return;
    cm_rbf_petsc *ps = *pp;
    KSPDestroy(&ps->ksp);
    MatDestroy(&ps->A);
    for (int a = 0; a < 4; ++a) VecDestroy(&ps->q1[a]);
    VecScatterDestroy(&ps->to_all);
    VecDestroy(&ps->all);
    free(ps->full_out);
    free(ps);
    *pp = NULL;
}

cm_status cm_rbf_petsc_setup(cm_context *ctx, cm_rbf *r, int threads)
{
    cm_status st = cm_rbf_petsc_initialize(ctx);
    if (st != CM_OK) return st;
    /* the Schwarz preconditioner and Q1, on every rank (replicated) */
    st = cm_rbf_iterative_setup(ctx, r, threads);
    if (st != CM_OK) return st;
    cm_rbf_petsc *ps = calloc(1, sizeof *ps);
    if (!ps) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    ps->r = r;
    ps->threads = threads;
    const PetscInt m = (PetscInt)r->m;
    if ((size_t)m != r->m) {
        free(ps);
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_rbf_create: %zu centres exceed PETSc's index type",
                        r->m);
    }
    int rank, size;
    cm_rbf_petsc_rank(&rank, &size);
    ps->lo = (PetscInt)((long long)m * rank / size);
    ps->hi = (PetscInt)((long long)m * (rank + 1) / size);
    const PetscInt nloc = ps->hi - ps->lo;
    const double *q1 = cm_rbf_iterative_q1(r);
    ps->full_out = malloc(r->m * sizeof *ps->full_out);
    if (!ps->full_out) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
        goto done;
    }
    for (int a = 0; a < r->k; ++a) {
        PetscScalar *v;
        P(VecCreateMPI(PETSC_COMM_WORLD, nloc, m, &ps->q1[a]));
        P(VecGetArray(ps->q1[a], &v));
        memcpy(v, q1 + (size_t)a * r->m + (size_t)ps->lo, (size_t)nloc * sizeof *v);
        P(VecRestoreArray(ps->q1[a], &v));
    }
    P(VecScatterCreateToAll(ps->q1[0], &ps->to_all, &ps->all));
    P(MatCreateShell(PETSC_COMM_WORLD, nloc, nloc, m, m, ps, &ps->A));
    P(MatShellSetOperation(ps->A, MATOP_MULT, (void (*)(void))shell_mult));
    P(KSPCreate(PETSC_COMM_WORLD, &ps->ksp));
    P(KSPSetOptionsPrefix(ps->ksp, "cm_"));
    P(KSPSetOperators(ps->ksp, ps->A, ps->A));
    P(KSPSetType(ps->ksp, KSPFGMRES));
    const int R = r->opt.restart < 63 ? r->opt.restart : 63;
    P(KSPGMRESSetRestart(ps->ksp, R));
    P(KSPGMRESSetOrthogonalization(ps->ksp, KSPGMRESClassicalGramSchmidtOrthogonalization));
    P(KSPGMRESSetCGSRefinementType(ps->ksp, KSP_GMRES_CGS_REFINE_ALWAYS));
    P(KSPSetPCSide(ps->ksp, PC_RIGHT));
    P(KSPSetNormType(ps->ksp, KSP_NORM_UNPRECONDITIONED));
    P(KSPSetInitialGuessNonzero(ps->ksp, PETSC_FALSE));
    P(KSPSetConvergenceTest(ps->ksp, converged, ps, NULL));
    PC pc;
    P(KSPGetPC(ps->ksp, &pc));
    P(PCSetType(pc, PCSHELL));
    P(PCShellSetContext(pc, ps));
    P(PCShellSetApply(pc, shell_pc));
    P(PCShellSetName(pc, "cadmorph two-level restricted Schwarz"));
    P(KSPSetFromOptions(ps->ksp));
    /* our convergence test again: KSPSetFromOptions may have replaced it */
    P(KSPSetConvergenceTest(ps->ksp, converged, ps, NULL));
    P(KSPSetUp(ps->ksp));
done:
    if (st != CM_OK) {
        cm_rbf_petsc_destroy(&ps);
        return st;
    }
    r->petsc = ps;
    return CM_OK;
}

/* Whole vector of v on every rank into out (m doubles). */
static PetscErrorCode to_full(cm_rbf_petsc *ps, Vec v, double *out)
{
    const PetscScalar *a;
    PetscCall(gather(ps, v, &a));
    memcpy(out, a, ps->r->m * sizeof *out);
    PetscCall(VecRestoreArrayRead(ps->all, &a));
    return 0;
}

/* One component: restart cycles as solve_group in rbf_iterative.c.
 * state: 1 converged, 2 at the floor, 3 stagnated, 4 max iterations. */
static cm_status solve_one(cm_context *ctx, cm_rbf_petsc *ps, const double *f, double fmax_all,
                           double *w, double *q, int *iters_out, double *res_out,
                           double *floor_out, int *state_out)
{
    const cm_rbf *r = ps->r;
    const cm_rbf_options *o = &r->opt;
    const size_t m = r->m, k = (size_t)r->k, nloc = (size_t)(ps->hi - ps->lo);
    cm_status st = CM_OK;
    Vec F = NULL, W = NULL, AW = NULL, RV = NULL, DW = NULL, T = NULL;
    PetscScalar *a;
    P(VecDuplicate(ps->q1[0], &F));
    P(VecDuplicate(F, &W));
    P(VecDuplicate(F, &AW));
    P(VecDuplicate(F, &RV));
    P(VecDuplicate(F, &DW));
    P(VecDuplicate(F, &T));
    P(VecGetArray(F, &a));
    memcpy(a, f + ps->lo, nloc * sizeof *a);
    P(VecRestoreArray(F, &a));
    P(VecSet(W, 0.0));
    P(VecSet(AW, 0.0));
    int iters = 0, state = 0;
    double prev = INFINITY, res = 0.0, fl = 0.0;
    const double fn = fmax_all > 0.0 ? fmax_all : 1.0;
    for (int cycle = 0;; ++cycle) {
        if (cycle > 0) P(apply_a(ps, W, AW, 0, 0));
        P(VecWAXPY(RV, -1.0, AW, F));
        P(project(ps, RV));
        PetscReal rinf, r2;
        P(VecNorm(RV, NORM_INFINITY, &rinf));
        res = fmax_all > 0.0 ? rinf / fmax_all : 0.0;
        if (res <= o->tolerance) {
            state = 1;
            break;
        }
        if (cycle > 0) {
            P(VecCopy(W, T));
            P(VecAbs(T));
            P(apply_a(ps, T, DW, 0, 0));
            PetscReal afl;
            P(VecNorm(DW, NORM_INFINITY, &afl));
            fl = DBL_EPSILON * afl / fn;
            if (res > 0.5 * prev) state = res <= 10.0 * fl ? 2 : 3;
            else if (iters >= o->max_iterations) state = res <= 10.0 * fl ? 2 : 4;
            if (state) break;
        }
        cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve (PETSc): cycle %d: %d iterations, residual %.3g",
               cycle, iters, res);
        prev = res;
        P(VecNorm(RV, NORM_2, &r2));
        ps->target = 0.5 * o->tolerance * fn * (r2 / rinf);
        const int R = o->restart < 63 ? o->restart : 63;
        int room = o->max_iterations - iters;
        P(KSPSetTolerances(ps->ksp, 0.0, 0.0, PETSC_DEFAULT, room < R ? room : R));
        P(KSPSolve(ps->ksp, RV, DW));
        PetscInt its;
        P(KSPGetIterationNumber(ps->ksp, &its));
        iters += (int)its;
        P(VecAXPY(W, 1.0, DW));
    }
    /* polynomial: R q = Q1'(f - A w) with the A w of the last true residual */
    P(VecWAXPY(RV, -1.0, AW, F));
    PetscScalar t[4];
    P(VecMDot(RV, (PetscInt)k, ps->q1, t));
    for (int i = (int)k - 1; i >= 0; --i) {
        double s = t[i];
        for (size_t j = (size_t)i + 1; j < k; ++j) s -= r->qr[j * m + (size_t)i] * q[j];
        q[i] = s / r->qr[(size_t)i * m + (size_t)i];
    }
    /* the residual at the centres, f - A w - P q, on the rows of each rank */
    P(VecGetArray(RV, &a));
    for (size_t i = 0; i < nloc; ++i) {
        size_t g = (size_t)ps->lo + i;
        a[i] -= q[0] + q[1] * r->c[g] + q[2] * r->c[m + g] + q[3] * r->c[2 * m + g];
    }
    P(VecRestoreArray(RV, &a));
    PetscReal e;
    P(VecNorm(RV, NORM_INFINITY, &e));
    /* the plain-sum floor, as the serial solver reports it */
    P(VecCopy(W, T));
    P(VecAbs(T));
    P(apply_a(ps, T, DW, 0, 1));
    PetscReal afl;
    P(VecNorm(DW, NORM_INFINITY, &afl));
    fl = fmax(fl, fmax_all > 0.0 ? DBL_EPSILON * afl / fmax_all : 0.0);
    P(to_full(ps, W, w));
    *iters_out = iters;
    *res_out = fmax_all > 0.0 ? e / fmax_all : 0.0;
    *floor_out = fl;
    *state_out = state;
done:
    VecDestroy(&F), VecDestroy(&W), VecDestroy(&AW), VecDestroy(&RV), VecDestroy(&DW);
    VecDestroy(&T);
    return st;
}

cm_status cm_rbf_petsc_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f, double *w,
                             double *q)
{
    cm_rbf_petsc *ps = r->petsc;
    const size_t m = r->m, k = (size_t)r->k;
    const cm_rbf_options *o = &r->opt;
    double fmax_all = 0.0;
    for (size_t i = 0; i < nc * m; ++i) fmax_all = fmax(fmax_all, fabs(f[i]));
    ps->matvecs = 0;
    int maxit = 0, floor_hit = 0, stagnated = 0, maxed = 0;
    double worst = 0.0, floor_max = 0.0;
    cm_status st = CM_OK;
    for (size_t c = 0; c < nc && st == CM_OK; ++c) {
        int it = 0, state = 0;
        double res = 0.0, fl = 0.0;
        st = solve_one(ctx, ps, f + c * m, fmax_all, w + c * m, q + c * k, &it, &res, &fl, &state);
        if (it > maxit) maxit = it;
        worst = fmax(worst, res);
        floor_max = fmax(floor_max, fl);
        floor_hit |= state == 2;
        stagnated |= state == 3;
        maxed |= state == 4;
    }
    if (st != CM_OK) return st;
    const int R = o->restart < 63 ? o->restart : 63;
    r->stats.iterations = maxit;
    r->stats.matvecs = ps->matvecs;
    r->stats.residual = worst;
    r->stats.floor = floor_max;
    r->stats.floor_limited = floor_hit && worst > o->tolerance;
    r->stats.memory_bytes = cm_rbf_schwarz_bytes(cm_rbf_iterative_pc(r)) + m * k * 8 +
                            (size_t)(2 * R + 8) * (size_t)(ps->hi - ps->lo) * 8 + 2 * m * 8;
    if (worst > o->tolerance && !r->stats.floor_limited)
        st = cm_error(ctx, CM_WARNING,
                      "cm_rbf_solve: the PETSc solver %s after %d iterations at a relative "
                      "residual of %.3g (tolerance %.3g, attainable floor %.3g)",
                      stagnated ? "stagnated" : maxed ? "reached max_iterations" : "stopped",
                      maxit, worst, o->tolerance, floor_max);
    return st;
}

int cm_rbf_petsc_evaluate(const cm_rbf *r, size_t n, const double *p, double *out, int threads)
{
    int rank, size;
    cm_rbf_petsc_rank(&rank, &size);
    const size_t nc = (size_t)r->ncomp;
    if (size < 2 || n * nc > (size_t)0x7fffffff) return 0; /* all on this rank */
    int *counts = malloc(2 * (size_t)size * sizeof *counts);
    if (!counts) return 0;
    int *displs = counts + size;
    for (int q = 0; q < size; ++q) {
        size_t lo = n * (size_t)q / (size_t)size, hi = n * (size_t)(q + 1) / (size_t)size;
        counts[q] = (int)((hi - lo) * nc);
        displs[q] = (int)(lo * nc);
    }
    const size_t lo = n * (size_t)rank / (size_t)size, hi = n * (size_t)(rank + 1) / (size_t)size;
    /* compensated sums, as cm_rbf_iterative_evaluate, on this rank's points */
    for (int g = 0; g < r->ncomp; g += 4) {
        int ng = r->ncomp - g < 4 ? r->ncomp - g : 4;
        cm_rbf_kernel_sum_acc(r->m, r->c, r->w + (size_t)g * r->m, ng, hi - lo, p + lo, n,
                              out + lo * nc + (size_t)g, nc, threads);
    }
    int ok = MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, out, counts, displs, MPI_DOUBLE,
                            PETSC_COMM_WORLD) == MPI_SUCCESS;
    free(counts);
    return ok;
}
