/* The iterative r^3 solver distributed over MPI ranks through PETSc:
 * KSPFGMRES on a MatShell whose rows are split over the ranks, the two-level restricted
 * Schwarz preconditioner of rbf_schwarz.c as a PCSHELL, the polynomial block handled in its
 * null space as in iterative/rbf_fgmres.c.
 *
 * The mathematics is the serial solver's, step for step, so that both take the same
 * iterations and agree to round-off: the operator is Pi A on range(Pi) (Pi = I - Q1 Q1'),
 * the preconditioner Pi M, classical Gram-Schmidt with one refinement, and the restarts are
 * ours: each restart cycle is one KSPSolve (at most `restart` iterations, so PETSc never
 * restarts by itself) on the true projected residual, stopped by our test on FGMRES's
 * 2-norm estimate against the max-norm target, as solve_group in iterative/rbf_fgmres.c does.
 * The serial solver runs up to four components in lock step so that one kernel sum serves
 * them all; here they form one block-diagonal system (vectors interleaved by row), which
 * keeps that saving (solving them one by one cost 4x the CPU of the serial solve at
 * m = 9.7k) at the price of one joint Krylov space: measured, the same iterations as the
 * slowest component serially.
 *
 * Distribution: every rank holds all centres (3 m doubles: replicated data is cheap beside
 * m^2 kernel pairs) and owns a block of rows; a matvec gathers x to all ranks and each sums
 * its rows, so the O(m^2) work is divided by the ranks. The preconditioner is split by
 * subdomains: every rank builds the kD-tree, the local sets and the coarse factor (cheap,
 * and identical on all ranks), but the local factorisations - most of the set-up - only of
 * its own run of subdomains (contiguous leaves of about equal cost, r->pc_parts); an
 * application does the coarse solve on every rank, the own local solves, and one
 * MPI_Allreduce of the g m corrections, which gives every rank the whole M x bit for bit
 * as one rank computes it (each leaf centre gets one term; rbf_schwarz.c). The rows of the
 * matvec stay in the centres' order, so the reduction moves the whole vector (g m doubles,
 * as the gather does): fine on one node. For many nodes the design is to number the rows
 * by Schwarz leaves, so that a rank's rows are its subdomains' leaves and the reduction
 * shrinks to the overlap halo, and to replace the gather by a treecode's far field. */
#include "cadmorph/parallel.h"
#include "rbf_internal.h"

#include <float.h>
#include <math.h>
#include <petscksp.h>
#include <stdlib.h>
#include <string.h>

/* The PETSc objects for g components in lock step (one joint system, see solve). */
typedef struct group {
    int g;
    Mat A;             /* MatShell: Pi A on each component */
    KSP ksp;
    Vec q1[16];        /* g k distributed vectors: Q1's column a in component c's slots */
    Vec all;           /* sequential copy of a whole vector on every rank */
    VecScatter to_all;
} group;

struct cm_rbf_petsc {
    const cm_rbf *r;
    int threads;
    PetscInt lo, hi;   /* rows of this rank */
    group grp[4];      /* by component count - 1, made on first use */
    group *cur;        /* the group of the running solve */
    double *soa_in, *soa_out; /* 4 x m: whole vectors by component */
    double target;     /* the running cycle's stopping target on the 2-norm estimate */
    int matvecs;       /* products with A since the solve began */
};

#define P(call) CM_PETSC_TRY("cm_rbf", call)

/* v -= Q1 (Q1' v) on every component, twice, as project() in iterative/rbf_fgmres.c. */
static PetscErrorCode project(cm_rbf_petsc *ps, Vec v)
{
    const int n = ps->cur->g * ps->r->k;
    PetscScalar s[16];
    for (int pass = 0; pass < 2; ++pass) {
        PetscCall(VecMDot(v, n, ps->cur->q1, s));
        for (int a = 0; a < n; ++a) s[a] = -s[a];
        PetscCall(VecMAXPY(v, n, s, ps->cur->q1));
    }
    return 0;
}

/* The whole of x (distributed, components interleaved by row) on every rank, by component
 * into soa (g x m). */
static PetscErrorCode gather(cm_rbf_petsc *ps, Vec x, double *soa)
{
    group *gr = ps->cur;
    const size_t m = ps->r->m, g = (size_t)gr->g;
    const PetscScalar *a;
    PetscCall(VecScatterBegin(gr->to_all, x, gr->all, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(gr->to_all, x, gr->all, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGetArrayRead(gr->all, &a));
    for (size_t i = 0; i < m; ++i)
        for (size_t c = 0; c < g; ++c) soa[c * m + i] = a[i * g + c];
    PetscCall(VecRestoreArrayRead(gr->all, &a));
    return 0;
}

/* y = A x on this rank's rows for every component (compensated sums, as the serial matvec:
 * the same rows come out bit for bit); plain: ordinary sums (the floor estimate); then Pi
 * if proj. */
static PetscErrorCode apply_a(cm_rbf_petsc *ps, Vec x, Vec y, int proj, int plain)
{
    const cm_rbf *r = ps->r;
    const int g = ps->cur->g;
    PetscScalar *ya;
    PetscCall(gather(ps, x, ps->soa_in));
    PetscCall(VecGetArray(y, &ya));
    const size_t n = (size_t)(ps->hi - ps->lo);
    if (plain)
        cm_rbf_kernel_sum(r->kernel, 3, r->m, r->c, ps->soa_in, g, n, r->c + ps->lo, r->m, ya,
                          (size_t)g, ps->threads);
    else
        cm_rbf_kernel_sum_acc(r->m, r->c, ps->soa_in, g, n, r->c + ps->lo, r->m, ya, (size_t)g,
                              ps->threads);
    PetscCall(VecRestoreArray(y, &ya));
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

/* The other ranks' local corrections, summed into out on every rank. */
static int sum_ranks(void *arg, double *out, size_t n)
{
    (void)arg;
    if (n > (size_t)0x7fffffff) return -1;
    return MPI_Allreduce(MPI_IN_PLACE, out, (int)n, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD) !=
           MPI_SUCCESS;
}

/* y = Pi M x: the coarse solve and this rank's subdomains, the local corrections summed
 * over the ranks; each rank keeps its rows. */
static PetscErrorCode shell_pc(PC pc, Vec x, Vec y)
{
    cm_rbf_petsc *ps;
    PetscCall(PCShellGetContext(pc, &ps));
    const size_t m = ps->r->m, g = (size_t)ps->cur->g;
    PetscScalar *ya;
    PetscCall(gather(ps, x, ps->soa_in));
    int ranks = 1;
    cm_parallel_rank(NULL, &ranks);
    if (cm_rbf_schwarz_apply_sum(cm_rbf_iterative_pc(ps->r), ps->r, (int)g, ps->soa_in,
                                 ps->soa_out, ps->threads, ranks > 1 ? sum_ranks : NULL,
                                 NULL) != 0)
        SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "MPI_Allreduce of the Schwarz corrections failed");
    PetscCall(VecGetArray(y, &ya));
    for (size_t i = 0; i < (size_t)(ps->hi - ps->lo); ++i)
        for (size_t c = 0; c < g; ++c) ya[i * g + c] = ps->soa_out[c * m + (size_t)ps->lo + i];
    PetscCall(VecRestoreArray(y, &ya));
    return project(ps, y);
}

/* The inner loop's stop: FGMRES's residual estimate below the cycle's target (the
 * iteration limit is KSP's own max_it, set per cycle). */
static PetscErrorCode converged(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason *reason,
                                void *vps)
{
    (void)ksp;
    const cm_rbf_petsc *ps = vps;
    *reason = it > 0 && rnorm <= ps->target ? KSP_CONVERGED_ATOL : KSP_CONVERGED_ITERATING;
    return 0;
}

static void group_destroy(group *gr)
{
    KSPDestroy(&gr->ksp);
    MatDestroy(&gr->A);
    for (int a = 0; a < 16; ++a) VecDestroy(&gr->q1[a]);
    VecScatterDestroy(&gr->to_all);
    VecDestroy(&gr->all);
    gr->g = 0;
}

void cm_rbf_petsc_destroy(cm_rbf_petsc **pp)
{
    if (!pp || !*pp) return;
    cm_rbf_petsc *ps = *pp;
    for (int g = 0; g < 4; ++g) group_destroy(&ps->grp[g]);
    free(ps->soa_in);
    free(ps->soa_out);
    free(ps);
    *pp = NULL;
}

/* The operator, Q1 and the solver for g components in lock step. */
static cm_status group_create(cm_context *ctx, cm_rbf_petsc *ps, int g)
{
    group *gr = &ps->grp[g - 1];
    if (gr->g == g) return CM_OK;
    const cm_rbf *r = ps->r;
    const PetscInt m = (PetscInt)r->m, nloc = ps->hi - ps->lo;
    const double *q1 = cm_rbf_iterative_q1(r);
    cm_status st = CM_OK;
    gr->g = g;
    for (int c = 0; c < g; ++c)
        for (int a = 0; a < r->k; ++a) {
            Vec *v = &gr->q1[c * r->k + a];
            PetscScalar *x;
            P(VecCreateMPI(PETSC_COMM_WORLD, g * nloc, g * m, v));
            P(VecSetBlockSize(*v, g));
            P(VecSet(*v, 0.0));
            P(VecGetArray(*v, &x));
            for (PetscInt i = 0; i < nloc; ++i)
                x[i * g + c] = q1[(size_t)a * r->m + (size_t)(ps->lo + i)];
            P(VecRestoreArray(*v, &x));
        }
    P(VecScatterCreateToAll(gr->q1[0], &gr->to_all, &gr->all));
    P(MatCreateShell(PETSC_COMM_WORLD, g * nloc, g * nloc, g * m, g * m, ps, &gr->A));
    P(MatShellSetOperation(gr->A, MATOP_MULT, (void (*)(void))shell_mult));
    P(KSPCreate(PETSC_COMM_WORLD, &gr->ksp));
    P(KSPSetOptionsPrefix(gr->ksp, "cm_"));
    P(KSPSetOperators(gr->ksp, gr->A, gr->A));
    P(KSPSetType(gr->ksp, KSPFGMRES));
    const int R = r->opt.restart < 63 ? r->opt.restart : 63;
    P(KSPGMRESSetRestart(gr->ksp, R));
    P(KSPGMRESSetOrthogonalization(gr->ksp, KSPGMRESClassicalGramSchmidtOrthogonalization));
    P(KSPGMRESSetCGSRefinementType(gr->ksp, KSP_GMRES_CGS_REFINE_ALWAYS));
    P(KSPSetPCSide(gr->ksp, PC_RIGHT));
    P(KSPSetNormType(gr->ksp, KSP_NORM_UNPRECONDITIONED));
    P(KSPSetInitialGuessNonzero(gr->ksp, PETSC_FALSE));
    PC pc;
    P(KSPGetPC(gr->ksp, &pc));
    P(PCSetType(pc, PCSHELL));
    P(PCShellSetContext(pc, ps));
    P(PCShellSetApply(pc, shell_pc));
    P(PCShellSetName(pc, "cadmorph two-level restricted Schwarz"));
    P(KSPSetFromOptions(gr->ksp));
    /* ours after the options: KSPSetFromOptions may replace the test */
    P(KSPSetConvergenceTest(gr->ksp, converged, ps, NULL));
    P(KSPSetUp(gr->ksp));
done:
    if (st != CM_OK) group_destroy(gr);
    return st;
}

cm_status cm_rbf_petsc_setup(cm_context *ctx, cm_rbf *r, int threads)
{
    cm_status st = cm_parallel_initialize(ctx);
    if (st != CM_OK) return st;
    if ((size_t)(PetscInt)(4 * r->m) != 4 * r->m)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_rbf_create: %zu centres exceed PETSc's index type", r->m);
    /* Q1 on every rank, the Schwarz preconditioner's subdomains split over the ranks */
    int rank0 = 0, size0 = 1;
    cm_parallel_rank(&rank0, &size0);
    r->pc_part = rank0;
    r->pc_parts = size0;
    st = cm_rbf_iterative_setup(ctx, r, threads);
    if (st != CM_OK) return st;
    cm_rbf_petsc *ps = calloc(1, sizeof *ps);
    if (!ps) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    ps->r = r;
    ps->threads = threads;
    int rank, size;
    cm_parallel_rank(&rank, &size);
    ps->lo = (PetscInt)((long long)r->m * rank / size);
    ps->hi = (PetscInt)((long long)r->m * (rank + 1) / size);
    ps->soa_in = malloc(4 * r->m * sizeof *ps->soa_in);
    ps->soa_out = malloc(4 * r->m * sizeof *ps->soa_out);
    if (!ps->soa_in || !ps->soa_out) {
        cm_rbf_petsc_destroy(&ps);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    }
    r->petsc = ps;
    return CM_OK;
}

typedef struct outcome {
    int iters, state; /* state: 1 converged, 2 at the floor, 3 stagnated, 4 max iterations */
    double res, floor;
} outcome;

/* Components [c0, c0 + g) of f (nc x m SoA) as one block-diagonal system: one kernel sum
 * serves all of them, as in the serial solver's lock step. Restart cycles as solve_group in
 * iterative/rbf_fgmres.c; a cycle's inner loop stops when the joint estimate is below the smallest
 * of the components' targets (so each component's own estimate is too). */
static cm_status solve_group(cm_context *ctx, cm_rbf_petsc *ps, int g, const double *f,
                             double fmax_all, double *w, double *q, outcome *out)
{
    const cm_rbf *r = ps->r;
    const cm_rbf_options *o = &r->opt;
    const size_t m = r->m, k = (size_t)r->k, nloc = (size_t)(ps->hi - ps->lo);
    cm_status st = group_create(ctx, ps, g);
    if (st != CM_OK) return st;
    group *gr = ps->cur = &ps->grp[g - 1];
    Vec F = NULL, W = NULL, AW = NULL, RV = NULL, DW = NULL, T = NULL;
    PetscScalar *a;
    P(VecDuplicate(gr->q1[0], &F));
    P(VecDuplicate(F, &W));
    P(VecDuplicate(F, &AW));
    P(VecDuplicate(F, &RV));
    P(VecDuplicate(F, &DW));
    P(VecDuplicate(F, &T));
    P(VecGetArray(F, &a));
    for (size_t i = 0; i < nloc; ++i)
        for (int c = 0; c < g; ++c) a[i * (size_t)g + (size_t)c] = f[(size_t)c * m + (size_t)ps->lo + i];
    P(VecRestoreArray(F, &a));
    P(VecSet(W, 0.0));
    P(VecSet(AW, 0.0));
    int iters = 0, state = 0;
    double prev = INFINITY, res = 0.0, fl = 0.0;
    const double fn = fmax_all > 0.0 ? fmax_all : 1.0;
    PetscReal rinf[4], r2[4], afl[4];
    for (int cycle = 0;; ++cycle) {
        if (cycle > 0) P(apply_a(ps, W, AW, 0, 0));
        P(VecWAXPY(RV, -1.0, AW, F));
        P(project(ps, RV));
        P(VecStrideNormAll(RV, NORM_INFINITY, rinf));
        res = 0.0;
        for (int c = 0; c < g; ++c) res = fmax(res, rinf[c] / fn);
        if (fmax_all == 0.0 || res <= o->tolerance) {
            state = 1;
            break;
        }
        if (cycle > 0) {
            P(VecCopy(W, T));
            P(VecAbs(T));
            P(apply_a(ps, T, DW, 0, 0));
            P(VecStrideNormAll(DW, NORM_INFINITY, afl));
            /* the worst component decides, as the serial stats do */
            fl = 0.0;
            for (int c = 0; c < g; ++c) fl = fmax(fl, DBL_EPSILON * afl[c] / fn);
            if (res > 0.5 * prev) state = res <= 10.0 * fl ? 2 : 3;
            else if (iters >= o->max_iterations) state = res <= 10.0 * fl ? 2 : 4;
            if (state) break;
        }
        cm_log(ctx, CM_LOG_DEBUG,
               "cm_rbf_solve (PETSc): components %d, cycle %d: %d iterations, residual %.3g",
               g, cycle, iters, res);
        prev = res;
        P(VecStrideNormAll(RV, NORM_2, r2));
        ps->target = INFINITY;
        for (int c = 0; c < g; ++c)
            if (rinf[c] / fn > o->tolerance)
                ps->target = fmin(ps->target, 0.5 * o->tolerance * fn * (r2[c] / rinf[c]));
        const int R = o->restart < 63 ? o->restart : 63;
        int room = o->max_iterations - iters;
        P(KSPSetTolerances(gr->ksp, 0.0, 0.0, PETSC_DEFAULT, room < R ? room : R));
        P(KSPSolve(gr->ksp, RV, DW));
        PetscInt its;
        P(KSPGetIterationNumber(gr->ksp, &its));
        iters += (int)its;
        P(VecAXPY(W, 1.0, DW));
    }
    cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve (PETSc): components %d: %d iterations, residual %.3g",
           g, iters, res);
    /* polynomial: R q = Q1'(f - A w) with the A w of the last true residual */
    P(VecWAXPY(RV, -1.0, AW, F));
    PetscScalar t[16];
    P(VecMDot(RV, (PetscInt)((size_t)g * k), gr->q1, t));
    for (int c = 0; c < g; ++c) {
        double *qc = q + (size_t)c * k;
        for (int i = (int)k - 1; i >= 0; --i) {
            double s = t[(size_t)c * k + (size_t)i];
            for (size_t j = (size_t)i + 1; j < k; ++j) s -= r->qr[j * m + (size_t)i] * qc[j];
            qc[i] = s / r->qr[(size_t)i * m + (size_t)i];
        }
    }
    /* the residual at the centres, f - A w - P q, on the rows of each rank */
    P(VecGetArray(RV, &a));
    for (size_t i = 0; i < nloc; ++i) {
        size_t gi = (size_t)ps->lo + i;
        for (int c = 0; c < g; ++c) {
            const double *qc = q + (size_t)c * k;
            a[i * (size_t)g + (size_t)c] -=
                qc[0] + qc[1] * r->c[gi] + qc[2] * r->c[m + gi] + qc[3] * r->c[2 * m + gi];
        }
    }
    P(VecRestoreArray(RV, &a));
    PetscReal e;
    P(VecNorm(RV, NORM_INFINITY, &e));
    /* the plain-sum floor, as the serial solver reports it */
    P(VecCopy(W, T));
    P(VecAbs(T));
    P(apply_a(ps, T, DW, 0, 1));
    PetscReal pfl;
    P(VecNorm(DW, NORM_INFINITY, &pfl));
    fl = fmax(fl, fmax_all > 0.0 ? DBL_EPSILON * pfl / fmax_all : 0.0);
    P(gather(ps, W, w));
    out->iters = iters;
    out->res = fmax_all > 0.0 ? e / fmax_all : 0.0;
    out->floor = fl;
    out->state = state;
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
    /* without it the evaluation would never take the treecode where the serial one does:
     * interior nodes 1.1e-9 of the range apart on bracket 60.6k (RESULTS.md, RBF solvers) */
    cm_rbf_iterative_scales_begin(r, 0, fmax_all);
    ps->matvecs = 0;
    int maxit = 0, floor_hit = 0, stagnated = 0, maxed = 0, gmax = 0;
    double worst = 0.0, floor_max = 0.0;
    cm_status st = CM_OK;
    for (size_t c0 = 0; c0 < nc && st == CM_OK; c0 += 4) {
        const int g = nc - c0 < 4 ? (int)(nc - c0) : 4;
        outcome oc = {0, 0, 0.0, 0.0};
        st = solve_group(ctx, ps, g, f + c0 * m, fmax_all, w + c0 * m, q + c0 * k, &oc);
        if (g > gmax) gmax = g;
        if (oc.iters > maxit) maxit = oc.iters;
        worst = fmax(worst, oc.res);
        floor_max = fmax(floor_max, oc.floor);
        floor_hit |= oc.state == 2;
        stagnated |= oc.state == 3;
        maxed |= oc.state == 4;
    }
    if (st != CM_OK) return st;
    const int R = o->restart < 63 ? o->restart : 63;
    r->stats.iterations = maxit;
    r->stats.matvecs = ps->matvecs;
    r->stats.residual = worst;
    r->stats.floor = floor_max;
    r->stats.floor_limited = floor_hit && worst > o->tolerance;
    r->stats.memory_bytes = cm_rbf_schwarz_bytes(cm_rbf_iterative_pc(r)) + m * k * 8 +
                            (size_t)gmax * ((size_t)(2 * R + 8) * (size_t)(ps->hi - ps->lo) + 3 * m) * 8;
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
    cm_parallel_rank(&rank, &size);
    const size_t nc = (size_t)r->ncomp;
    if (size < 2 || n * nc > (size_t)0x7fffffff) return 0; /* all on this rank */
    /* collective: not cut into interruptible chunks (every rank would have to stop together) */
    if (cm_rbf_iterative_evaluate_fast(r, n, p, out, threads, NULL)) return 1;
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

int cm_rbf_petsc_evaluate_transpose(const cm_rbf *r, size_t n, const double *p, int nc,
                                    const double *v, double *out, int threads)
{
    int rank, size;
    cm_parallel_rank(&rank, &size);
    const size_t m = r->m, ncs = (size_t)nc;
    if (size < 2 || m * ncs > (size_t)0x7fffffff) return 0; /* all on this rank */
    /* as cm_rbf_petsc_evaluate: the treecode on every rank if it is taken (deterministic),
     * else each rank its block of the targets, here the centres, gathered to all */
    if (cm_rbf_iterative_transpose_fast(r, n, p, nc, v, out, threads, NULL)) return 1;
    int *counts = malloc(2 * (size_t)size * sizeof *counts);
    if (!counts) return 0;
    int *displs = counts + size;
    for (int q = 0; q < size; ++q) {
        size_t lo = m * (size_t)q / (size_t)size, hi = m * (size_t)(q + 1) / (size_t)size;
        counts[q] = (int)((hi - lo) * ncs);
        displs[q] = (int)(lo * ncs);
    }
    const size_t lo = m * (size_t)rank / (size_t)size, hi = m * (size_t)(rank + 1) / (size_t)size;
    for (int g = 0; g < nc; g += 4) {
        int ng = nc - g < 4 ? nc - g : 4;
        cm_rbf_kernel_sum_acc(n, p, v + (size_t)g * n, ng, hi - lo, r->c + lo, m,
                              out + lo * ncs + (size_t)g, ncs, threads);
    }
    int ok = MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, out, counts, displs, MPI_DOUBLE,
                            PETSC_COMM_WORLD) == MPI_SUCCESS;
    free(counts);
    return ok;
}
