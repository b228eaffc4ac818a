// paths.cpp: limb paths and gripper goals from C++ (limber.hpp's Line, Ptp and Goal), on
// simarm with its block: a PTP over the table, a straight line back, the fingers open wide
// (clamped) and a PTP to the block, a goal that stalls on it. Prints "ptp: <sentence>",
// "line: <sentence>", "goal: <RESULT> <CAUSE>".
#include <limber.hpp>

#include <chrono>
#include <cstdio>

int main() {
    try {
        using std::chrono::seconds;
        limber::LimbProxy limb("simarm/limb/0");
        limber::GripperProxy grip("simarm/gripper/0");
        const limber_vec3 down{0, 0, -1}, forward{1, 0, 0};
        limber_done d = limb.WaitDone(limb.Ptp({0.4, 0.0, 0.3}, down, forward), seconds(60));
        std::printf("ptp: %s\n", d.sentence);
        if (d.result != LIMBER_RESULT_REACHED) return 1;
        d = limb.WaitDone(limb.Line(0.4, 0.1, 0.25, 0.2), seconds(60));
        std::printf("line: %s\n", d.sentence);
        if (d.result != LIMBER_RESULT_REACHED) return 1;
        grip.WaitDone(grip.Goal(1.0), seconds(60));
        d = limb.WaitDone(limb.Ptp({0.36, 0.06, 0.17}, down, forward), seconds(60));
        if (d.result != LIMBER_RESULT_REACHED) return 1;
        d = grip.WaitDone(grip.Goal(0.0, 5.0), seconds(60));
        std::printf("goal: %s %s\n", d.result == LIMBER_RESULT_STALLED ? "STALLED" : "other",
                    limber_status_name(d.cause));
        return 0;
    } catch (const limber::Error& e) {
        std::fprintf(stderr, "paths_cpp: %s\n", e.what());
        return 1;
    }
}
