/* Parameters of the benchmark models at t: linear interpolation between the values the issue
 * fixes for t = 0 and t = 1. Shared by the CAD models and the structured hex meshes. */
#include "cadmorph/models.h"

#include <string.h>

static double lerp(double a, double b, double t) { return a + (b - a) * t; }

void cm_model_bore_at(double t, cm_model_bore *p)
{
    p->radius = lerp(0.6, 1.0, t);
    p->tilt_deg = lerp(0.0, 25.0, t);
}

void cm_model_pipe_at(double t, cm_model_pipe *p)
{
    p->radius = 0.5;
    p->inlet = 2.0;
    p->bend_radius = lerp(2.0, 1.5, t);
    p->bend_deg = lerp(90.0, 135.0, t);
    p->outlet = lerp(2.0, 4.0, t);
}

void cm_model_bracket_at(double t, cm_model_bracket *p)
{
    p->leg = 5.0;
    p->width = 1.0;
    p->height = 3.0;
    p->fillet = lerp(0.5, 1.0, t);
    p->hole_radius = lerp(0.4, 0.6, t);
    p->hole1_x = lerp(3.0, 3.5, t);
    p->hole2_y = 3.0;
}

int cm_model_known(const char *name)
{
    return name && (!strcmp(name, "bore") || !strcmp(name, "pipe") || !strcmp(name, "bracket"));
}

const char *cm_model_list(void) { return "bore, pipe, bracket"; }
