// device.cpp: the C++ layer's typed answers. WaitOutcome gives a limber::Status (name, text,
// carried out); TryWaitForData says "nothing new" without throwing; LimbProxy::Reach and
// SetPose of limber::Vec3; and, once the test has stopped the driver (it writes a line to
// stdin), the error's what() says "the driver is gone" once. Bounded waits.
#include <limber.hpp>

#include <iostream>
#include <string>

using namespace std::chrono_literals;

int main() {
    try {
        limber::ActArrayProxy arm("pioneer/actarray/0");
        limber::LimbProxy limb("pioneer/limb/0");
        limber::Status s = arm.WaitOutcome(arm.MoveTo(0, 0.1), 5s);
        std::cout << "move: " << s.name() << " carried out " << s.carried_out() << " text "
                  << s.text() << " raw " << (s == LIMBER_STATUS_OK) << "\n";
        int empty = 0;
        arm.GetData();
        for (int i = 0; i < 50; ++i) {
            if (!arm.TryWaitForData(0ms)) ++empty;
        }
        std::cout << "no news without an exception: " << (empty > 0) << "\n";
        limber::Vec3 pos{0.38, 0.1, 0.22}, down{0, 0, -1}, orient{0.94, 0.34, 0};
        limber_limb_reach r = limb.Reach(pos, down, orient);
        std::cout << "reach: adjusted " << (r.orientation_adjustment > 0) << "\n";
        limber::Status p = limb.WaitOutcome(limb.SetPose(pos, down, orient), 5s);
        std::cout << "setpose: " << p.name() << " carried out " << p.carried_out() << "\n";
        try {
            limb.Reach({5, 5, 5}, down, orient);
            std::cout << "reach far: no refusal\n";
        } catch (const limber::Error& e) {
            std::cout << "reach far: " << limber::Status(e.refusal()).name() << "\n";
        }
        std::cout << "ready" << std::endl;
        std::string line;
        std::getline(std::cin, line);
        try {
            arm.WaitForData(10s);
            arm.WaitForData(10s);
            std::cout << "gone: no error\n";
        } catch (const limber::Error& e) {
            std::cout << "gone: " << e.what() << "\n";
        }
    } catch (const limber::Error& e) {
        std::cerr << "device.cpp: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
