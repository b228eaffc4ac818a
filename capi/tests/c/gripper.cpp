// gripper.cpp: the C++ client of the four-language test (c_programs.rs): it commands the
// arm gripper. Connects to the gripper and the arm, checks two refusals (brakes on an arm
// without brakes; reading while a state is borrowed), prints "ready", and on the line "go"
// opens the gripper if it is closed, closes it, waits for each outcome and until the
// gripper reports it closed, and prints "gripper: done". On the line "report" it reads a
// fresh state of each device and prints "seen: <the six joint positions> gripper <state>".
#include <limber.hpp>

#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>

using namespace std::chrono_literals;

namespace {

void Expect(const std::string& word) {
    std::string line;
    if (!std::getline(std::cin, line) || line != word)
        throw std::runtime_error("expected the line " + word + ", got " + line);
}

// Sends a gripper command, checks that it is carried out and waits (bounded) for `state`.
void MoveTo(limber::GripperProxy& gripper, limber::ActArrayProxy& arm, limber_ticket ticket,
            uint32_t state, const char* what) {
    uint32_t status = gripper.WaitOutcome(ticket, 5s);
    std::cout << "gripper: " << what << " " << limber::StatusText(status) << std::endl;
    if (status != LIMBER_STATUS_OK) throw std::runtime_error(std::string(what) + " refused");
    uint32_t last = 0;
    auto deadline = std::chrono::steady_clock::now() + 60s;
    while (std::chrono::steady_clock::now() < deadline)
        if ((last = gripper.WaitForData(2s).state) == state) return;
    auto joint = arm.GetData().actuators[5];
    throw std::runtime_error(std::string("the gripper did not ") + what + " within 60 s: state " +
                             std::to_string(last) + ", its joint at " + std::to_string(joint.position) +
                             " with state bits " + std::to_string(joint.state));
}

}  // namespace

int main() try {
    limber::GripperProxy gripper("pioneer/gripper/1");
    limber::ActArrayProxy arm("pioneer/actarray/0");
    try {
        arm.SetBrakesConfig(true);
        std::cerr << "gripper: brakes on an arm without brakes were not refused" << std::endl;
        return 1;
    } catch (const limber::Error& e) {
        if (e.code() != LIMBER_CODE_REFUSED || e.refusal() != LIMBER_STATUS_UNSUPPORTED) throw;
    }
    {
        // A state in place, without a copy: while it is held, reading states is refused.
        auto held = gripper.Borrow();
        try {
            gripper.GetData();
            std::cerr << "gripper: GetData while a state is borrowed was not refused" << std::endl;
            return 1;
        } catch (const limber::Error& e) {
            if (e.code() != LIMBER_CODE_BORROWED) throw;
        }
        if (held->header.seq == 0) throw std::runtime_error("a borrowed state without a sequence number");
    }
    gripper.GetData();  // released by the destructor
    std::cout << "ready" << std::endl;
    Expect("go");
    if (gripper.GetData().state == LIMBER_GRIPPER_STATE_CLOSED)
        MoveTo(gripper, arm, gripper.Open(), LIMBER_GRIPPER_STATE_OPEN, "open");
    MoveTo(gripper, arm, gripper.Close(), LIMBER_GRIPPER_STATE_CLOSED, "close");
    std::cout << "gripper: done" << std::endl;

    Expect("report");
    auto d = arm.WaitForData(2s);
    auto g = gripper.WaitForData(2s);
    std::printf("seen:");
    for (uint32_t j = 0; j < d.actuators_count; j++) std::printf(" %.9f", d.actuators[j].position);
    std::printf(" gripper %u\n", g.state);
    return 0;
} catch (const std::exception& e) {
    std::cerr << "gripper: " << e.what() << std::endl;
    return 1;
}
