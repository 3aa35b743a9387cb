// The rod formulation's validation cases at benchmark resolution (the
// default 23 segments, 0.25 m, 0.02 s steps): the same cases tests/test_rod.cpp
// asserts (tests/rod_cases.h), reported as one JSON object:
//   cantilever: [{beta, tip_error}]   tip error as a fraction of L vs the heavy elastica
//   pendulum_period_error             hanging chain, first mode vs T1 = 4π/2.4048·sqrt(L/g)
//   energy_drift                      (max E - E0)/(μgL²/2), released from horizontal, no drag, 10 s
//   energy_kept_2s                    undamped hanging chain (E = 0) swinging in its first mode at 10% of L:
//                                     energy in play after 2 s over its start (rodcases::swing), with
//                                     BDF2 (simulation.rod_integrator: bdf2)
//   swing_log_decrement               the same swing's logarithmic decrement per period
//   swing_period_error                its period vs T1
//   damped_kinetic_energy_j           after 5 s with drag 1/s
//   max_stretch                       max |l/l0 - 1| over every case
//
//   bench_rod [--json] [--swing euler,bdf2 --rod-substeps 2,8,24]
//
// --swing (with --rod-substeps): the undamped swing again for each
// integrator and rod substep count, how the default was chosen (issue 29:
// the default keeps >= 90% of the energy after 2 s; docs/physics.md):
//   swing_choices: [{integrator, rod_substeps, energy_kept_2s, log_decrement}]
#include "tests/rod_cases.h"

#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::string> split(const std::string& list) {
    std::vector<std::string> out;
    std::stringstream in(list);
    for (std::string item; std::getline(in, item, ',');) out.push_back(item);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace hp::rodcases;
    bool json = false;
    std::vector<std::string> integrators, substeps{"2"};
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--json") == 0) json = true;
        else if (std::strcmp(argv[i], "--swing") == 0 && i + 1 < argc) integrators = split(argv[++i]);
        else if (std::strcmp(argv[i], "--rod-substeps") == 0 && i + 1 < argc) substeps = split(argv[++i]);
        else {
            std::fprintf(stderr, "usage: bench_rod [--json] [--swing euler,bdf2 [--rod-substeps 2,8,24]]\n");
            return 1;
        }
    }
    double maxStretch = 0;
    std::string cases;
    for (double beta : {0.5, 2.0, 8.0, 32.0, 128.0}) {
        const Cantilever c = cantilever(beta, 2);
        maxStretch = std::max(maxStretch, c.maxStretch);
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s{\"beta\": %g, \"tip_error\": %.5f}", cases.empty() ? "" : ", ", beta,
                      double(c.error));
        cases += buf;
    }
    const Pendulum p = pendulum();
    const Energy e = energy();
    const Swing w = swing(rodSettings(0.f, 0.f, false), 0.1);  // the default integrator (BDF2; Euler keeps 0.39)
    maxStretch = std::max({maxStretch, p.maxStretch, e.maxStretch, w.maxStretch});
    std::string choices;
    for (const std::string& integrator : integrators)
        for (const std::string& k : substeps) {
            hp::GuideSettings s = rodSettings(0.f, 0.f, false);
            s.rodIntegrator = hp::parseRodIntegrator(integrator);
            s.rodSubsteps = std::stoi(k);
            const Swing c = swing(s, 0.1);
            char buf[160];
            std::snprintf(buf, sizeof buf,
                          "%s{\"integrator\": \"%s\", \"rod_substeps\": %d, \"energy_kept_2s\": %.4f, "
                          "\"log_decrement\": %.5f}",
                          choices.empty() ? "" : ", ", integrator.c_str(), s.rodSubsteps, c.energyKept2s,
                          c.logDecrement);
            choices += buf;
        }
    if (!choices.empty()) choices = ", \"swing_choices\": [" + choices + "]";
    if (json)
        std::printf("{\"cantilever\": [%s], \"pendulum_period_error\": %.5f, \"energy_drift\": %.6f, "
                    "\"damped_kinetic_energy_j\": %.3e, \"energy_kept_2s\": %.4f, \"swing_log_decrement\": %.5f, "
                    "\"swing_period_error\": %.5f, \"max_stretch\": %.3e%s}\n",
                    cases.c_str(), p.error, e.drift, e.dampedKinetic, w.energyKept2s, w.logDecrement, w.periodError,
                    maxStretch, choices.c_str());
    else
        std::printf("cantilever %s\npendulum period %.4f s vs %.4f s (error %.4f)\nenergy drift %.6f, damped KE "
                    "%.3e J\nundamped swing: energy kept after 2 s %.4f, log decrement %.5f, period error %.5f\n"
                    "max stretch %.3e\n%s%s",
                    cases.c_str(), p.period, p.reference, p.error, e.drift, e.dampedKinetic, w.energyKept2s,
                    w.logDecrement, w.periodError, maxStretch, choices.empty() ? "" : "swing choices: ",
                    choices.empty() ? "" : (choices.substr(2) + "\n").c_str());
    return 0;
}
