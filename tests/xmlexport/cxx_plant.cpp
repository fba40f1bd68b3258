// C++ use of the plant model (c_blocks/plant.h): this translation unit is
// compiled with g++ and linked against plant.c compiled as C, as a C++
// runtime (OpenPLC v3) would. It fails to link if plant.h loses its
// extern "C" guards.
//
// Expected value, closed form: the drive is a first-order lag (time constant
// LAG) on the speed reference maxvel * V / 10 V; from rest, after t >> LAG
// the position is v * (t - LAG * (1 - exp(-t / LAG))).
#include <cmath>
#include <cstdio>
#include "plant.h"

int main()
{
    double v[PA_N] = {0};
    v[PA_MAXVEL] = 100000.0;      // counts/s at +10 V
    v[PA_LAG] = 0.005;
    v[PA_DAMP] = 0.1;
    v[PA_CAMLO] = 1.0;            // no cam
    v[PA_CPR] = 4000.0;
    v[PA_T] = -1.0;               // not started
    const int16_t dac = 3277;     // 1.0001 V
    for (int i = 0; i < 1000; i++)
        plant_step_array(v, dac, 0.001);
    const double speed = 100000.0 * dac / 32767.0;
    const double t = 1.0, lag = 0.005;
    const double expect = speed * (t - lag * (1.0 - std::exp(-t / lag)));
    const double got = v[PA_COUNTER];
    const bool ok = std::fabs(got - expect) <= 0.01 * expect;
    std::printf("%s: cxx-plant-step-array (counter %.0f after 1 s at 1 V, expected %.0f +-1%%)\n",
                ok ? "PASS" : "FAIL", got, expect);

    // the struct API: same run, same expectation
    plant_params p;
    plant_defaults(&p);
    plant s;
    plant_init(&s, &p);
    for (int i = 0; i < 1000; i++)
        plant_step(&s, dac, 0.001);
    const double got2 = plant_counter(&s);
    const bool ok2 = std::fabs(got2 - expect) <= 0.01 * expect;
    std::printf("%s: cxx-plant-struct-api (counter %.0f, expected %.0f +-1%%)\n",
                ok2 ? "PASS" : "FAIL", got2, expect);
    return ok && ok2 ? 0 : 1;
}
