// lease.cpp: the C++ face of control leases: limber::Lease (acquire in the constructor,
// release in the destructor), Holder(), a refusal as limber::Error, Preempted(). Prints
// "all C++ lease steps ok" at the end; exits non-zero at the first step that fails.
#include <limber.hpp>

#include <chrono>
#include <cstdio>
#include <string>

using namespace std::chrono_literals;

static int bad(const char* what) {
    std::fprintf(stderr, "lease_cpp: %s\n", what);
    return 1;
}

int main() try {
    limber::ActArrayProxy mine("pioneer/actarray/0");
    limber::ActArrayProxy other("pioneer/actarray/0");
    {
        limber::Lease lease(mine, "cpp-holder", 5s);
        auto who = other.Holder();
        if (!who || who->client_id != mine.ClientId() || std::string(who->name) != "cpp-holder")
            return bad("the holder is not cpp-holder");
        if (other.WaitOutcome(other.MoveTo(2, 0.2), 5s) != LIMBER_STATUS_LEASED)
            return bad("the other's move is not refused as LEASED");
        try {
            other.Acquire("other", 2s);
            return bad("the other's Acquire did not throw");
        } catch (const limber::Error& e) {
            if (e.code() != LIMBER_CODE_REFUSED || e.refusal() != LIMBER_STATUS_LEASED ||
                std::string(e.what()).find("cpp-holder") == std::string::npos)
                return bad(e.what());
            std::printf("refused: %s\n", e.what());
        }
        lease.KeepLease();
    }
    if (other.Holder()) return bad("the lease outlived its guard");
    {
        limber::Lease lease(mine, "cpp-holder", 5s);
        lease.Release();
        if (other.Holder()) return bad("the lease outlived its Release()");
    }
    // Under the program's name; Release() gives it back.
    other.Acquire(5s);
    std::printf("holder: %s\n", other.Holder()->name);
    other.Release();

    // Preemption: mine turns joint 0 slowly, other stops it.
    auto slow = mine.MoveAtSpeed(0, 0.2);
    if (mine.WaitOutcome(slow, 5s) != LIMBER_STATUS_OK) return bad("the slow move failed");
    if (other.WaitOutcome(other.MoveAtSpeed(0, 0.0), 5s) != LIMBER_STATUS_OK) return bad("the stop failed");
    std::optional<uint64_t> by;
    for (int i = 0; i < 200 && !by; i++) {
        mine.WaitForData(5s);
        by = mine.Preempted(slow);
    }
    if (by != other.ClientId()) return bad("the slow move is not preempted by the other");
    std::printf("all C++ lease steps ok\n");
    return 0;
} catch (const limber::Error& e) {
    std::fprintf(stderr, "lease_cpp: %s\n", e.what());
    return 1;
}
