/* The yardstick of benchmarks/bench_integrator.py: a plain classical RK4 for a chain of
 * N equal beads with Hertz contacts (Eq. 1), optional Kuwabara-Kono dissipation, free
 * ends, written the way one would write it in C: no contact-event refinement, no checks.
 * It records the N-1 contact forces and the energy every record_every steps, as the
 * library does, so that its accuracy can be compared too.
 *
 * Build (done by the benchmark): cc -O3 -shared -fPIC rk4_chain.c -o rk4_chain.so -lm
 */
#include <math.h>
#include <stdlib.h>

static void slopes(int n, const double *u, const double *v, double inverse_mass,
                   double kappa, double damping, double *acc, double *force)
{
    double previous = 0.0;
    for (int j = 0; j < n - 1; j++) {
        double delta = u[j] - u[j + 1];
        double total = 0.0;
        if (delta > 0.0) {
            double root = sqrt(delta);
            total = kappa * delta * root;
            if (damping > 0.0) {
                total += damping * root * (v[j] - v[j + 1]);
                if (total < 0.0)
                    total = 0.0;
            }
        }
        force[j] = total;
        acc[j] = (previous - total) * inverse_mass;
        previous = total;
    }
    acc[n - 1] = previous * inverse_mass;
}

static double energy(int n, const double *u, const double *v, double mass, double kappa)
{
    double total = 0.0;
    for (int p = 0; p < n; p++)
        total += 0.5 * mass * v[p] * v[p];
    for (int j = 0; j < n - 1; j++) {
        double delta = u[j] - u[j + 1];
        if (delta > 0.0)
            total += 0.4 * kappa * delta * delta * sqrt(delta);
    }
    return total;
}

/* Integrates n_steps steps of dt in place; writes (n_steps / record_every + 1) samples
 * of the n-1 contact forces to out_force and of E_kin + E_pot to out_energy (the
 * dissipated energy is not tracked). Returns 0, or -1 when out of memory. */
int rk4_chain(int n, double mass, double kappa, double damping, double dt, long n_steps,
              long record_every, double *u, double *v, double *out_force, double *out_energy)
{
    double *work = malloc(7 * (size_t)n * sizeof(double));
    if (!work)
        return -1;
    double *acc = work, *us = work + n, *vs = work + 2 * n, *su = work + 3 * n;
    double *sv = work + 4 * n, *force = work + 5 * n;
    double inverse_mass = 1.0 / mass, half = 0.5 * dt, sixth = dt / 6.0;
    long sample = 0;
    slopes(n, u, v, inverse_mass, kappa, damping, acc, force);
    for (int j = 0; j < n - 1; j++)
        out_force[j] = force[j];
    out_energy[sample++] = energy(n, u, v, mass, kappa);
    for (long step = 1; step <= n_steps; step++) {
        slopes(n, u, v, inverse_mass, kappa, damping, acc, force);
        for (int p = 0; p < n; p++) {
            su[p] = v[p];
            sv[p] = acc[p];
            us[p] = u[p] + half * v[p];
            vs[p] = v[p] + half * acc[p];
        }
        for (int stage = 1; stage <= 2; stage++) {
            double h = stage == 2 ? dt : half;
            slopes(n, us, vs, inverse_mass, kappa, damping, acc, force);
            for (int p = 0; p < n; p++) {
                su[p] += 2.0 * vs[p];
                sv[p] += 2.0 * acc[p];
                us[p] = u[p] + h * vs[p];
                vs[p] = v[p] + h * acc[p];
            }
        }
        slopes(n, us, vs, inverse_mass, kappa, damping, acc, force);
        for (int p = 0; p < n; p++) {
            u[p] += sixth * (su[p] + vs[p]);
            v[p] += sixth * (sv[p] + acc[p]);
        }
        if (step % record_every == 0) {
            slopes(n, u, v, inverse_mass, kappa, damping, acc, force);
            for (int j = 0; j < n - 1; j++)
                out_force[sample * (n - 1) + j] = force[j];
            out_energy[sample++] = energy(n, u, v, mass, kappa);
        }
    }
    free(work);
    return 0;
}
