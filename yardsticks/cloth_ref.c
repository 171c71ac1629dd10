/* The cloth-N workload (docs/benchmarks.md) as a plain hand-written C kernel:
 * a spring list of index pairs, T threads, each accumulating its share of the springs into
 * a private full-size force buffer, then a parallel pass that sums the buffers and does the
 * semi-implicit Euler update. It is the kind of kernel the performance issue quotes as its
 * yardstick ("a hand-written C kernel, 2 threads, private force buffers"), written here to
 * measure this machine against the issue's: run it beside `hooke bench cloth`.
 *
 *     gcc -O3 -march=native -fopenmp -o /tmp/cloth_ref yardsticks/cloth_ref.c -lm
 *     OMP_NUM_THREADS=2 /tmp/cloth_ref 256 400
 *
 * Prints one JSON object with the fields of `hooke bench cloth --json`. The centre y after
 * 200 steps agrees with hooke's to about 1e-9 relative (the summation order differs). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct {
    int i, j;
    double rest;
} Spring;

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* The workload's start: particle i*n + j at (i h, 1, j h), at rest. */
static void place(double *x, double *v, int n, double h) {
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double *p = x + 3 * (i * n + j);
            p[0] = i * h, p[1] = 1.0, p[2] = j * h;
        }
    memset(v, 0, sizeof(double) * 3 * (size_t)n * n);
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    const int n = argc > 1 ? atoi(argv[1]) : 256;
    const int steps = argc > 2 ? atoi(argv[2]) : 200;
    if (n < 3 || steps < 1) {
        fprintf(stderr, "usage: cloth_ref N STEPS (N >= 3, STEPS >= 1)\n");
        return 2;
    }
    const int np = n * n;
    const double h = 1.0 / (n - 1), ks = 1000.0, kd = 0.01, dt = 1e-5, g = -9.81;
    const double m = 1.0 / np;
    double *x = malloc(sizeof(double) * 3 * np), *v = malloc(sizeof(double) * 3 * np);
    place(x, v, n, h);
    const long ns = 2L * n * (n - 1) + 2L * (n - 1) * (n - 1) + 2L * n * (n - 2);
    Spring *s = malloc(sizeof(Spring) * ns);
    long k = 0;
    /* Each particle's springs to its later neighbours, particle by particle: the natural
     * order of a mesh's spring list. */
    const int offs[6][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}, {2, 0}, {0, 2}};
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int o = 0; o < 6; o++) {
                int a = i, b = j, c = i + offs[o][0], d = j + offs[o][1];
                if (o == 3) a = i + 1, b = j, c = i, d = j + 1; /* (i+1,j)-(i,j+1) */
                if (a >= n || b >= n || c < 0 || c >= n || d >= n) continue;
                int p = a * n + b, q = c * n + d;
                double dx = x[3 * p] - x[3 * q], dy = x[3 * p + 1] - x[3 * q + 1],
                       dz = x[3 * p + 2] - x[3 * q + 2];
                s[k++] = (Spring){p, q, sqrt(dx * dx + dy * dy + dz * dz)};
            }
    if (k != ns) {
        fprintf(stderr, "built %ld springs, expected %ld\n", k, ns);
        return 1;
    }
    const int threads = omp_get_max_threads();
    double *fbuf = malloc(sizeof(double) * 3 * (size_t)np * threads);
    const int pin0 = 0, pin1 = n - 1;
    double *step_s = malloc(sizeof(double) * steps);

    double t0 = 0.0;
    for (int phase = 0; phase < 2; phase++) {
        /* phase 0: warm-up on the same state, then reset; phase 1: measured. */
        int count = phase == 0 ? 20 : steps;
        if (phase == 1) {
            place(x, v, n, h);
            t0 = now();
        }
        for (int it = 0; it < count; it++) {
            double ts = now();
#pragma omp parallel
            {
                int t = omp_get_thread_num();
                double *f = fbuf + 3 * (size_t)np * t;
                memset(f, 0, sizeof(double) * 3 * np);
#pragma omp for schedule(static)
                for (long e = 0; e < ns; e++) {
                    int i = s[e].i, j = s[e].j;
                    double dx = x[3 * i] - x[3 * j], dy = x[3 * i + 1] - x[3 * j + 1],
                           dz = x[3 * i + 2] - x[3 * j + 2];
                    double dvx = v[3 * i] - v[3 * j], dvy = v[3 * i + 1] - v[3 * j + 1],
                           dvz = v[3 * i + 2] - v[3 * j + 2];
                    double len = sqrt(dx * dx + dy * dy + dz * dz);
                    if (len < 1e-12) continue;
                    double inv = 1.0 / len, ux = dx * inv, uy = dy * inv, uz = dz * inv;
                    double sc = -ks * (len - s[e].rest) - kd * (dvx * ux + dvy * uy + dvz * uz);
                    double fx = sc * ux, fy = sc * uy, fz = sc * uz;
                    f[3 * i] += fx, f[3 * i + 1] += fy, f[3 * i + 2] += fz;
                    f[3 * j] -= fx, f[3 * j + 1] -= fy, f[3 * j + 2] -= fz;
                }
                /* the implied barrier: every buffer is complete */
#pragma omp for schedule(static)
                for (int p = 0; p < np; p++) {
                    if (p == pin0 || p == pin1) continue;
                    double fx = 0, fy = m * g, fz = 0;
                    for (int b = 0; b < threads; b++) {
                        const double *fb = fbuf + 3 * (size_t)np * b + 3 * (size_t)p;
                        fx += fb[0], fy += fb[1], fz += fb[2];
                    }
                    double *vp = v + 3 * p, *xp = x + 3 * p;
                    vp[0] += dt * fx / m, vp[1] += dt * fy / m, vp[2] += dt * fz / m;
                    xp[0] += dt * vp[0], xp[1] += dt * vp[1], xp[2] += dt * vp[2];
                }
            }
            if (phase == 1) step_s[it] = now() - ts;
        }
    }
    double total = now() - t0;
    qsort(step_s, steps, sizeof(double), cmp_double);
    int c = (n / 2) * n + n / 2;
    printf("{\"n\":%d,\"steps\":%d,\"threads\":%d,\"springs\":%ld,\"steps_per_s\":%.3f,"
           "\"spring_updates_per_s\":%.1f,\"median_spring_updates_per_s\":%.1f,"
           "\"center_y\":%.12f}\n",
           n, steps, threads, ns, steps / total, ns * steps / total,
           ns / step_s[steps / 2], x[3 * c + 1]);
    for (int p = 0; p < np; p++)
        if (!isfinite(x[3 * p + 1])) {
            fprintf(stderr, "particle %d is not finite\n", p);
            return 1;
        }
    return 0;
}
