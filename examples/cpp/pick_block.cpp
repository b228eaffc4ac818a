// pick_block.cpp: the paper's Listing 2 -- pick up a block, move it to another position
// and put it down -- with limber's C++ proxies (README.md beside this file). The paper
// found the block with a laser scan; here its position is given (default 0.38 0.10).
//
// Usage: pick_block_cpp [BLOCK_X BLOCK_Y]
// Exit status: 0 done, 2 out of reach (the arm went home), 1 any other failure.
#include <limber.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>

using namespace std::chrono_literals;

// Where the paper slept ("sleep(10) -- this could actually poll the arm to check"),
// limber waits for the command's outcome, then until the limb stops moving.
static limber_limb_data WaitForLimb(limber::LimbProxy& Limb, limber_ticket Ticket) {
    uint32_t Status = LIMBER_STATUS_OK;
    try {
        Status = Limb.WaitOutcome(Ticket, 30s);
    } catch (const limber::Error& e) {
        if (e.code() != LIMBER_CODE_OUTCOME_MISSED) throw;  // missed: applied, then superseded
    }
    // The state published with the outcome: out of reach shows as LIMBER_LIMB_STATE_OOR.
    limber_limb_data Data = Limb.GetData();
    if (Status == LIMBER_STATUS_OUT_OF_REACH) return Data;
    if (Status != LIMBER_STATUS_OK && Status != LIMBER_STATUS_CLAMPED)
        throw std::runtime_error("limb command refused: " + limber::StatusText(Status));
    auto Deadline = std::chrono::steady_clock::now() + 30s;
    while (Data.state == LIMBER_LIMB_STATE_MOVING) {
        if (std::chrono::steady_clock::now() > Deadline)
            throw std::runtime_error("the limb did not stop within 30 s");
        Data = Limb.WaitForData(30s);
    }
    std::cout << "limb at (" << Data.position.x << ", " << Data.position.y << ", "
              << Data.position.z << ")" << std::endl;
    return Data;
}

static void WaitForGripper(limber::GripperProxy& Gripper, limber_ticket Ticket, uint32_t Want) {
    uint32_t Status = Gripper.WaitOutcome(Ticket, 30s);
    if (Status != LIMBER_STATUS_OK)
        throw std::runtime_error("gripper command refused: " + limber::StatusText(Status));
    auto Deadline = std::chrono::steady_clock::now() + 30s;
    for (auto Data = Gripper.GetData(); Data.state != Want; Data = Gripper.WaitForData(30s))
        if (std::chrono::steady_clock::now() > Deadline)
            throw std::runtime_error("the gripper did not finish within 30 s");
    std::cout << "gripper " << (Want == LIMBER_GRIPPER_STATE_CLOSED ? "closed" : "open") << std::endl;
}

int main(int argc, char** argv) {
    double HandleHeight = 0.17;  // Height above floor that the arm should grab at
    limber_vec3 CentrePoint{0.38, 0.10, 0.0};  // The middle of the block
    limber_vec3 DropPoint{0.38, -0.10, 0.0};   // Where to put it
    if (argc == 3) {
        CentrePoint.x = std::atof(argv[1]);
        CentrePoint.y = std::atof(argv[2]);
    } else if (argc != 1) {
        std::cerr << "usage: pick_block_cpp [BLOCK_X BLOCK_Y]" << std::endl;
        return 1;
    }
    try {
        limber::LimbProxy Limb("pioneer/limb/0");
        limber::GripperProxy Gripper("pioneer/gripper/1");

        WaitForLimb(Limb, Limb.MoveHome());
        Limb.RequestGeometry();
        limber_vec3 Base = Limb.GetGeom().base_pos;

        // Calculate the orientation vector: across the block, radially outward from the
        // limb's base (the paper: from the block's closest point to its centre).
        auto Orientation = [&](const limber_vec3& p) {
            double x = p.x - Base.x, y = p.y - Base.y, n = std::hypot(x, y);
            return limber_vec3{x / n, y / n, 0.0};
        };
        limber_vec3 Orient = Orientation(CentrePoint);

        WaitForGripper(Gripper, Gripper.Open(), LIMBER_GRIPPER_STATE_OPEN);
        // Calculate a point about 5 cm above the target point.
        auto Ticket = Limb.SetPose(CentrePoint.x, CentrePoint.y, HandleHeight + 0.05, 0, 0, -1,
                                   Orient.x, Orient.y, 0);
        // Wait for it to get there
        if (WaitForLimb(Limb, Ticket).state == LIMBER_LIMB_STATE_OOR) {
            std::cout << "Target out of reach, terminating" << std::endl;
            WaitForLimb(Limb, Limb.MoveHome());
            return 2;
        }
        // Move to grasp position
        WaitForLimb(Limb, Limb.SetPose(CentrePoint.x, CentrePoint.y, HandleHeight, 0, 0, -1,
                                       Orient.x, Orient.y, 0));
        // Grip the block
        WaitForGripper(Gripper, Gripper.Close(), LIMBER_GRIPPER_STATE_CLOSED);
        // Lift it, move it, put it down
        WaitForLimb(Limb, Limb.SetPose(CentrePoint.x, CentrePoint.y, HandleHeight + 0.05, 0, 0,
                                       -1, Orient.x, Orient.y, 0));
        Orient = Orientation(DropPoint);
        WaitForLimb(Limb, Limb.SetPose(DropPoint.x, DropPoint.y, HandleHeight + 0.05, 0, 0, -1,
                                       Orient.x, Orient.y, 0));
        WaitForLimb(Limb, Limb.SetPose(DropPoint.x, DropPoint.y, HandleHeight, 0, 0, -1,
                                       Orient.x, Orient.y, 0));
        // Release the block
        WaitForGripper(Gripper, Gripper.Open(), LIMBER_GRIPPER_STATE_OPEN);
        WaitForLimb(Limb, Limb.SetPose(DropPoint.x, DropPoint.y, HandleHeight + 0.05, 0, 0, -1,
                                       Orient.x, Orient.y, 0));
        // And home again
        WaitForLimb(Limb, Limb.MoveHome());
        std::cout << "done: block picked up and put down" << std::endl;
        return 0;
    } catch (const limber::Error& e) {
        std::cerr << "pick_block_cpp: " << e.what() << " (code " << e.code() << ")" << std::endl;
    } catch (const std::exception& e) {
        std::cerr << "pick_block_cpp: " << e.what() << std::endl;
    }
    return 1;
}
