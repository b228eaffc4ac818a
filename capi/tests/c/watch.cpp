// watch.cpp: a C++ client that only watches while another commands: it asks for the arm's
// geometry, then reads the arm gripper's states until it has seen the gripper close and
// open again (within 60 s), asking for the geometry once more on the way.
#include <limber.hpp>

#include <iostream>
#include <stdexcept>

using namespace std::chrono_literals;

int main() try {
    limber::ActArrayProxy arm("pioneer/actarray/0");
    limber::GripperProxy gripper("pioneer/gripper/1");
    auto count = arm.RequestGeometry().actuators_count;
    try {
        arm.SetBrakesConfig(true);
        std::cerr << "watch: brakes on an arm without brakes were not refused" << std::endl;
        return 1;
    } catch (const limber::Error& e) {
        if (e.code() != LIMBER_CODE_REFUSED || e.refusal() != LIMBER_STATUS_UNSUPPORTED) throw;
    }
    {
        // A state in place, without a copy: while it is held, reading states is refused.
        auto held = gripper.Borrow();
        try {
            gripper.GetData();
            std::cerr << "watch: GetData while a state is borrowed was not refused" << std::endl;
            return 1;
        } catch (const limber::Error& e) {
            if (e.code() != LIMBER_CODE_BORROWED) throw;
        }
        if (held->header.seq == 0) throw std::runtime_error("a borrowed state without a sequence number");
    }
    gripper.GetData();  // released by the destructor
    std::cout << "watching; the arm has " << count << " actuators" << std::endl;
    bool closed = false;
    auto deadline = std::chrono::steady_clock::now() + 60s;
    while (std::chrono::steady_clock::now() < deadline) {
        auto state = gripper.WaitForData(5s).state;
        if (state == LIMBER_GRIPPER_STATE_CLOSED && !closed) {
            closed = true;
            count = arm.RequestGeometry(2s).actuators_count;
        } else if (closed && state == LIMBER_GRIPPER_STATE_OPEN) {
            std::cout << "saw the gripper close and open; the arm has " << count << " actuators"
                      << std::endl;
            return 0;
        }
    }
    std::cerr << "watch: the gripper did not close and open within 60 s" << std::endl;
    return 1;
} catch (const limber::Error& e) {
    std::cerr << "watch: " << e.what() << std::endl;
    return 1;
}
