// pick_block.cpp: the paper's Listing 2 -- find a block with the laser, pick it up, move
// it to another position and put it down -- with limber's C++ proxies (README.md beside
// this file).
//
// Usage: pick_block_cpp [LIMB GRIPPER LASER]  (default pioneer/limb/0 pioneer/gripper/1
// pioneer/ranger/0)
// Exit status: 0 done, 2 out of reach (the arm went home), 1 any other failure.
#include <limber.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

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
    if (!limber::Status(Status).carried_out())
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
    double BlockRadius = 0.02;   // From the closest point the laser sees to the block's centre
    limber_vec3 DropPoint{0.38, -0.10, 0.0};  // Where to put it
    std::string LimbName = "pioneer/limb/0", GripperName = "pioneer/gripper/1",
                LaserName = "pioneer/ranger/0";
    if (argc == 4) {
        LimbName = argv[1];
        GripperName = argv[2];
        LaserName = argv[3];
    } else if (argc != 1) {
        std::cerr << "usage: pick_block_cpp [LIMB GRIPPER LASER]" << std::endl;
        return 1;
    }
    try {
        limber::LaserProxy Laser(LaserName);
        limber::LimbProxy Limb(LimbName);
        limber::GripperProxy Gripper(GripperName);

        WaitForLimb(Limb, Limb.MoveHome());
        Limb.RequestGeometry();

        Laser.RequestGeom();
        limber_pose3 LaserPose = Laser.GetPose();
        Laser.Read();
        // Find the closest point in the laser scan
        uint32_t MinIndex = 0;
        for (uint32_t ii = 1; ii < Laser.GetCount(); ++ii) {
            if (Laser[ii] < Laser[MinIndex]) MinIndex = ii;
        }
        limber::Point2d Closest = Laser.GetPoint(MinIndex);
        Closest.px += LaserPose.position.x;
        Closest.py += LaserPose.position.y;
        // Calculate a point in the middle of the block
        double PreRange = Laser[MinIndex] + BlockRadius;
        double Bearing = Laser.GetMinAngle() + Laser.GetScanRes() * MinIndex;
        limber::Point2d CentrePoint;
        CentrePoint.px = PreRange * std::cos(Bearing);
        CentrePoint.py = PreRange * std::sin(Bearing);
        CentrePoint.px += LaserPose.position.x;
        CentrePoint.py += LaserPose.position.y;
        // Calculate the orientation vector: from the closest point to the centre
        limber::Point2d Orientation;
        Orientation.px = CentrePoint.px - Closest.px;
        Orientation.py = CentrePoint.py - Closest.py;
        std::cout << "found the block at (" << CentrePoint.px << ", " << CentrePoint.py << ")"
                  << std::endl;

        WaitForGripper(Gripper, Gripper.Open(), LIMBER_GRIPPER_STATE_OPEN);
        // Calculate a point about 5 cm above the target point.
        auto Ticket = Limb.SetPose(CentrePoint.px, CentrePoint.py, HandleHeight + 0.05, 0, 0, -1,
                                   Orientation.px, Orientation.py, 0);
        // Wait for it to get there
        if (WaitForLimb(Limb, Ticket).state == LIMBER_LIMB_STATE_OOR) {
            std::cout << "Target out of reach, terminating" << std::endl;
            WaitForLimb(Limb, Limb.MoveHome());
            return 2;
        }
        // Move to grasp position
        WaitForLimb(Limb, Limb.SetPose(CentrePoint.px, CentrePoint.py, HandleHeight, 0, 0, -1,
                                       Orientation.px, Orientation.py, 0));
        // Grip the block
        WaitForGripper(Gripper, Gripper.Close(), LIMBER_GRIPPER_STATE_CLOSED);
        // Lift it, move it, put it down
        WaitForLimb(Limb, Limb.SetPose(CentrePoint.px, CentrePoint.py, HandleHeight + 0.05, 0, 0,
                                       -1, Orientation.px, Orientation.py, 0));
        WaitForLimb(Limb, Limb.SetPose(DropPoint.x, DropPoint.y, HandleHeight + 0.05, 0, 0, -1,
                                       Orientation.px, Orientation.py, 0));
        WaitForLimb(Limb, Limb.SetPose(DropPoint.x, DropPoint.y, HandleHeight, 0, 0, -1,
                                       Orientation.px, Orientation.py, 0));
        // Release the block
        WaitForGripper(Gripper, Gripper.Open(), LIMBER_GRIPPER_STATE_OPEN);
        WaitForLimb(Limb, Limb.SetPose(DropPoint.x, DropPoint.y, HandleHeight + 0.05, 0, 0, -1,
                                       Orientation.px, Orientation.py, 0));
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
