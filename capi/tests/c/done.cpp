// done.cpp: how a motion ended, from C++ (limber.hpp's WaitDone). Moves joint 2 of the arm
// and prints "reached: <sentence>" and "error E tolerance T".
#include <limber.hpp>

#include <cmath>
#include <cstdio>

int main() {
    try {
        limber::ActArrayProxy arm("pioneer/actarray/0");
        const auto& geom = arm.RequestGeometry();
        const unsigned joint = 2;
        double target = geom.actuators[joint].home + 0.3;
        if (target > geom.actuators[joint].max) target = geom.actuators[joint].home - 0.3;
        limber_ticket t = arm.MoveTo(joint, target);
        limber_done d = arm.WaitDone(t, std::chrono::seconds(60));
        if (d.result != LIMBER_RESULT_REACHED) {
            std::fprintf(stderr, "done_cpp: not reached: %s\n", d.sentence);
            return 1;
        }
        std::printf("reached: %s\n", d.sentence);
        std::printf("error %.6f tolerance %.6f\n", std::fabs(d.error[joint]), d.tolerance);
        return 0;
    } catch (const limber::Error& e) {
        std::fprintf(stderr, "done_cpp: %s\n", e.what());
        return 1;
    }
}
