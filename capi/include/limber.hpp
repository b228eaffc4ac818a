/* limber.hpp: the limber client API for C++17, header-only, over the C API of
 * limber_client.h (link with `pkg-config --cflags --libs limber`).
 *
 * RAII proxies named like Player's: limber::ActArrayProxy, limber::LimbProxy,
 * limber::GripperProxy and limber::RangerProxy (limber::LaserProxy) connect in their
 * constructor and disconnect in their destructor.
 * Every failure throws limber::Error, which carries the limber_code (code()), its message
 * with the detail (what()) and, for a request the driver refused, the driver's
 * LIMBER_STATUS_* (refusal()). Timeouts are std::chrono durations.
 *
 * Commands return a limber_ticket at once; WaitOutcome(ticket, timeout) returns the
 * driver's verdict, a limber::Status (ok(), carried_out(), name(), text(); it converts to
 * the raw LIMBER_STATUS_*). A wait that may rightly end without news has a Try form that
 * returns std::optional instead of throwing (TryWaitForData).
 *
 * Control: Acquire(name, heartbeat) takes the device's lease (other clients are refused
 * as LIMBER_STATUS_LEASED), Renew()/KeepLease() keep it, Release() gives it back;
 * limber::Lease does both in its constructor and destructor. Holder() says who holds a
 * device, Preempted(ticket) whether another client cut a command's motion short.
 *
 * Thread-safety: as the C API's. A proxy is used by one thread at a time (it may be moved
 * to another thread between calls); different proxies work in different threads at once.
 */
#ifndef LIMBER_HPP
#define LIMBER_HPP

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "limber_client.h"

namespace limber {

/// A timeout or an age (converted to whole milliseconds, rounded up).
using Duration = std::chrono::nanoseconds;

/// How long connecting waits for a driver by default.
inline constexpr Duration kConnectTimeout = std::chrono::seconds(5);
/// How long a request waits for its reply by default.
inline constexpr Duration kRequestTimeout = std::chrono::seconds(2);
/// How long reading a state waits for a first one by default.
inline constexpr Duration kStateTimeout = std::chrono::seconds(2);

/// A failed call: its limber_code, message and detail, and the driver's reason if it
/// refused a request.
class Error : public std::runtime_error {
public:
    Error(limber_code code, const std::string& what, uint32_t refusal)
        : std::runtime_error(what), code_(code), refusal_(refusal) {}
    /// The limber_code (LIMBER_CODE_*).
    limber_code code() const noexcept { return code_; }
    /// The driver's LIMBER_STATUS_* when code() is LIMBER_CODE_REFUSED, else LIMBER_STATUS_OK.
    uint32_t refusal() const noexcept { return refusal_; }

private:
    limber_code code_;
    uint32_t refusal_;
};

/// The text of a driver's LIMBER_STATUS_*.
inline std::string StatusText(uint32_t status) { return limber_status_text(status); }

/// A command's outcome: the driver's LIMBER_STATUS_* with its name and text. Converts to
/// the raw code (uint32_t), so `status == LIMBER_STATUS_OK` reads as in C.
class Status {
public:
    /// The outcome of code `code` (a LIMBER_STATUS_*).
    constexpr explicit Status(uint32_t code = LIMBER_STATUS_OK) noexcept : code_(code) {}
    /// The raw LIMBER_STATUS_*.
    constexpr uint32_t code() const noexcept { return code_; }
    constexpr operator uint32_t() const noexcept { return code_; }
    /// Carried out exactly as asked (LIMBER_STATUS_OK).
    constexpr bool ok() const noexcept { return code_ == LIMBER_STATUS_OK; }
    /// Carried out: OK, or CLAMPED (a value clamped to a limit), or ADJUSTED (a limb pose's
    /// orientation turned to one the joints can hold).
    bool carried_out() const noexcept { return limber_status_is_carried_out(code_); }
    /// Its name as limber.h spells it without the prefix ("OUT_OF_REACH").
    std::string name() const { return limber_status_name(code_); }
    /// What it means ("the position lies beyond the limb's reach").
    std::string text() const { return limber_status_text(code_); }

private:
    uint32_t code_;
};

/// A point or a direction in the robot frame (m): limber.h's limber_vec3.
using Vec3 = limber_vec3;

namespace detail {
inline uint64_t Millis(Duration d) {
    if (d.count() <= 0) return 0;
    return static_cast<uint64_t>(std::chrono::ceil<std::chrono::milliseconds>(d).count());
}

/// Throws limber::Error for anything but LIMBER_CODE_OK.
inline void Check(limber_code code) {
    if (code == LIMBER_CODE_OK) return;
    std::string what = limber_strerror(code);
    std::string detail = limber_last_error();
    // The detail says more than the code's message, or the same again ("the driver is
    // gone"): never both the same.
    if (detail.find(what) != std::string::npos) {
        what = detail;
    } else if (!detail.empty()) {
        what += ": " + detail;
    }
    throw Error(code, what, code == LIMBER_CODE_REFUSED ? limber_last_refusal() : LIMBER_STATUS_OK);
}

#define LIMBER_HPP_TRAITS(Name, prefix, Data, Geom)                                           \
    struct Name {                                                                             \
        using Handle = limber_##prefix;                                                       \
        using DataType = Data;                                                                \
        using GeomType = Geom;                                                                \
        static constexpr auto connect = limber_##prefix##_connect;                            \
        static constexpr auto disconnect = limber_##prefix##_disconnect;                      \
        static constexpr auto state = limber_##prefix##_state;                                \
        static constexpr auto borrow = limber_##prefix##_borrow;                              \
        static constexpr auto release = limber_##prefix##_release;                            \
        static constexpr auto wait_state = limber_##prefix##_wait_state;                      \
        static constexpr auto wait_outcome = limber_##prefix##_wait_outcome;                  \
        static constexpr auto liveness = limber_##prefix##_liveness;                          \
        static constexpr auto driver_status = limber_##prefix##_driver_status;                \
        static constexpr auto geometry = limber_##prefix##_geometry;                          \
        static constexpr auto client_id = limber_##prefix##_client_id;                        \
        static constexpr auto acquire = limber_##prefix##_acquire;                            \
        static constexpr auto renew = limber_##prefix##_renew;                                \
        static constexpr auto keep_lease = limber_##prefix##_keep_lease;                      \
        static constexpr auto release_lease = limber_##prefix##_release_lease;                \
        static constexpr auto holder = limber_##prefix##_holder;                              \
        static constexpr auto preempted = limber_##prefix##_preempted;                        \
    }
LIMBER_HPP_TRAITS(ActArrayTraits, actarray, limber_actarray_data, limber_actarray_geom);
LIMBER_HPP_TRAITS(LimbTraits, limb, limber_limb_data, limber_limb_geom);
LIMBER_HPP_TRAITS(GripperTraits, gripper, limber_gripper_data, limber_gripper_geom);
LIMBER_HPP_TRAITS(RangerTraits, ranger, limber_ranger_data, limber_ranger_geom);
#undef LIMBER_HPP_TRAITS
}  // namespace detail

/// A state lent in place from shared memory (no copy) until this object is destroyed.
/// While it lives, the proxy's calls that read states throw LIMBER_CODE_BORROWED.
template <class T>
class Borrowed {
public:
    Borrowed(typename T::Handle* h, const typename T::DataType* data) : h_(h), data_(data) {}
    Borrowed(const Borrowed&) = delete;
    Borrowed& operator=(const Borrowed&) = delete;
    Borrowed(Borrowed&& o) noexcept : h_(std::exchange(o.h_, nullptr)), data_(o.data_) {}
    Borrowed& operator=(Borrowed&&) = delete;
    ~Borrowed() {
        if (h_ != nullptr) T::release(h_);
    }
    const typename T::DataType& operator*() const noexcept { return *data_; }
    const typename T::DataType* operator->() const noexcept { return data_; }

private:
    typename T::Handle* h_;
    const typename T::DataType* data_;
};

/// What every proxy does: connect, read and wait for states, wait for outcomes, liveness.
template <class T>
class BasicProxy {
public:
    /// The state struct of limber.h.
    using Data = typename T::DataType;
    /// The geometry struct of limber.h.
    using Geom = typename T::GeomType;

    /// Connects to `device` ("robot/interface/index") in `domain` (empty: LIMBER_DOMAIN,
    /// or "limber"), waiting up to `timeout` for a driver to offer it.
    explicit BasicProxy(const std::string& device, Duration timeout = kConnectTimeout,
                        const std::string& domain = "") {
        detail::Check(T::connect(device.c_str(), domain.empty() ? nullptr : domain.c_str(),
                                 detail::Millis(timeout), &h_));
    }
    BasicProxy(const BasicProxy&) = delete;
    BasicProxy& operator=(const BasicProxy&) = delete;
    BasicProxy(BasicProxy&& o) noexcept : h_(std::exchange(o.h_, nullptr)), geom_(o.geom_) {}
    BasicProxy& operator=(BasicProxy&& o) noexcept {
        std::swap(h_, o.h_);
        std::swap(geom_, o.geom_);
        return *this;
    }
    ~BasicProxy() { T::disconnect(h_); }

    /// The latest state (a copy), waiting up to `timeout` for a first one.
    Data GetData(Duration timeout = kStateTimeout) {
        Data d{};
        detail::Check(T::state(h_, detail::Millis(timeout), &d));
        return d;
    }
    /// The latest state in place, without a copy, until the returned object is destroyed.
    Borrowed<T> Borrow(Duration timeout = kStateTimeout) {
        const Data* p = nullptr;
        detail::Check(T::borrow(h_, detail::Millis(timeout), &p));
        return Borrowed<T>(h_, p);
    }
    /// Waits up to `timeout` for a state newer than the latest one taken; throws
    /// LIMBER_CODE_TIMEOUT when none came (see TryWaitForData, which does not).
    Data WaitForData(Duration timeout) {
        Data d{};
        detail::Check(T::wait_state(h_, detail::Millis(timeout), &d));
        return d;
    }
    /// Waits up to `timeout` for a state newer than the latest one taken: std::nullopt
    /// when none came in time (the driver lives but said nothing new); throws for every
    /// other failure (the driver gone, ...).
    std::optional<Data> TryWaitForData(Duration timeout) {
        Data d{};
        limber_code c = T::wait_state(h_, detail::Millis(timeout), &d);
        if (c == LIMBER_CODE_TIMEOUT) return std::nullopt;
        detail::Check(c);
        return d;
    }
    /// Waits up to `timeout` for the outcome of a command: the driver's verdict
    /// (status.carried_out(), status.name(), status.text(); it converts to the raw
    /// LIMBER_STATUS_*).
    Status WaitOutcome(limber_ticket ticket, Duration timeout) {
        uint32_t status = LIMBER_STATUS_OK;
        detail::Check(T::wait_outcome(h_, ticket, detail::Millis(timeout), &status));
        return Status(status);
    }
    /// Waits up to `timeout` for the outcome of a command, with the other client involved
    /// (the holder, by id and name, when it is LIMBER_STATUS_LEASED).
    limber_outcome WaitOutcomeDetail(limber_ticket ticket, Duration timeout) {
        limber_outcome o{};
        detail::Check(limber_device_outcome(h_, ticket, detail::Millis(timeout), &o));
        return o;
    }
    /// Waits up to `timeout` until the motion that the command of `ticket` started has
    /// ended: how (`result`, a LIMBER_RESULT_*; `cause`, a LIMBER_STATUS_*), each part's
    /// final position and error against the goal, the device's tolerance and a sentence.
    /// Throws for a refused command (LIMBER_CODE_REFUSED) and when it has not ended in
    /// time (LIMBER_CODE_TIMEOUT).
    limber_done WaitDone(limber_ticket ticket, Duration timeout) {
        limber_done d{};
        detail::Check(limber_device_wait_done(h_, ticket, detail::Millis(timeout), &d));
        return d;
    }
    /// Alive (a state younger than `max_age`), stale, gone, or no data yet.
    limber_liveness Liveness(Duration max_age) {
        limber_liveness l = LIMBER_LIVENESS_NO_DATA;
        detail::Check(T::liveness(h_, detail::Millis(max_age), &l));
        return l;
    }
    /// Whether the driver's process lives.
    limber_driver_status DriverStatus() {
        limber_driver_status s = LIMBER_DRIVER_STATUS_ABSENT;
        detail::Check(T::driver_status(h_, &s));
        return s;
    }
    /// Asks the driver for the geometry (and keeps it for GetGeom()).
    const Geom& RequestGeometry(Duration timeout = kRequestTimeout) {
        detail::Check(T::geometry(h_, detail::Millis(timeout), &geom_));
        return geom_;
    }
    /// This proxy's client id (as Holder() and Preempted() name clients).
    uint64_t ClientId() {
        uint64_t id = 0;
        detail::Check(T::client_id(h_, &id));
        return id;
    }
    /// Takes the device's control lease as `name` (1 to LIMBER_LEASE_NAME_MAX bytes):
    /// other clients' commands and device-changing requests are refused as
    /// LIMBER_STATUS_LEASED until Release(). Renew it at least every `heartbeat` (Renew(),
    /// or KeepLease() in a loop), or the driver stops the device and frees it. Held by
    /// another client: throws LIMBER_CODE_REFUSED with refusal() LIMBER_STATUS_LEASED and
    /// the holder's name in what().
    void Acquire(const std::string& name, Duration heartbeat) {
        detail::Check(T::acquire(h_, name.c_str(), detail::Millis(heartbeat)));
    }
    /// Takes the lease under this program's name.
    void Acquire(Duration heartbeat) {
        detail::Check(T::acquire(h_, nullptr, detail::Millis(heartbeat)));
    }
    /// The lease's heartbeat (throws LIMBER_CODE_LEASE_LOST when the lease ended).
    void Renew() { detail::Check(T::renew(h_)); }
    /// Renews the lease when a third of its heartbeat has passed; whether it did.
    bool KeepLease() {
        bool renewed = false;
        detail::Check(T::keep_lease(h_, &renewed));
        return renewed;
    }
    /// Gives the lease back (nothing happens without one).
    void Release() { detail::Check(T::release_lease(h_)); }
    /// Who holds the device's lease, if anybody.
    std::optional<limber_lease_holder> Holder() {
        limber_lease_holder h{};
        detail::Check(T::holder(h_, &h));
        if (h.client_id == 0) return std::nullopt;
        return h;
    }
    /// The client whose command cut short the motion of `ticket`'s command, if one did
    /// (as far as the outcomes that arrived tell; it does not wait).
    std::optional<uint64_t> Preempted(limber_ticket ticket) {
        bool preempted = false;
        uint64_t by = 0;
        detail::Check(T::preempted(h_, ticket, &preempted, &by));
        if (!preempted) return std::nullopt;
        return by;
    }
    /// The geometry of the last RequestGeometry() (zeros before).
    const Geom& GetGeom() const noexcept { return geom_; }
    /// The C handle, for the C API.
    typename T::Handle* get() const noexcept { return h_; }

protected:
    typename T::Handle* h_ = nullptr;
    Geom geom_{};
};

/// Player's ActArrayProxy: an actuator array.
class ActArrayProxy : public BasicProxy<detail::ActArrayTraits> {
public:
    using BasicProxy::BasicProxy;
    /// CMD POS: moves `joint` to `position` (rad or m).
    limber_ticket MoveTo(uint32_t joint, double position) {
        limber_ticket t{};
        detail::Check(limber_actarray_move_to(h_, joint, position, &t));
        return t;
    }
    /// CMD MULTI_POS: moves joints 0..n to `positions`.
    limber_ticket MoveToMulti(const std::vector<double>& positions) {
        limber_ticket t{};
        detail::Check(limber_actarray_move_to_multi(h_, positions.data(), positions.size(), &t));
        return t;
    }
    /// CMD SPEED: moves `joint` at `speed` (rad/s or m/s).
    limber_ticket MoveAtSpeed(uint32_t joint, double speed) {
        limber_ticket t{};
        detail::Check(limber_actarray_move_at_speed(h_, joint, speed, &t));
        return t;
    }
    /// CMD MULTI_SPEED: moves joints 0..n at `speeds`.
    limber_ticket MoveAtSpeedMulti(const std::vector<double>& speeds) {
        limber_ticket t{};
        detail::Check(limber_actarray_move_at_speed_multi(h_, speeds.data(), speeds.size(), &t));
        return t;
    }
    /// CMD TRAJ: follows a joint trajectory of `joints` (row-major `positions` of
    /// times.size() x joints.size(); `velocities`, `accelerations` the same or empty; the
    /// tolerances one per joint or empty): see limber_actarray_follow_trajectory.
    limber_ticket FollowTrajectory(const std::vector<uint32_t>& joints,
                                   const std::vector<double>& times,
                                   const std::vector<double>& positions,
                                   const std::vector<double>& velocities = {},
                                   const std::vector<double>& accelerations = {},
                                   const std::vector<double>& path_tolerance = {},
                                   const std::vector<double>& goal_tolerance = {},
                                   double goal_time_tolerance = 0.0, uint64_t start_ns = 0) {
        auto p = [](const std::vector<double>& v) { return v.empty() ? nullptr : v.data(); };
        limber_ticket t{};
        detail::Check(limber_actarray_follow_trajectory(
            h_, joints.data(), joints.size(), times.data(), times.size(), positions.data(),
            p(velocities), p(accelerations), p(path_tolerance), p(goal_tolerance),
            goal_time_tolerance, start_ns, &t));
        return t;
    }
    /// CMD TRAJ_SCALE: the speed scaling of trajectories (0 pauses, 1 nominal).
    limber_ticket SetTrajectoryScale(double scale) {
        limber_ticket t{};
        detail::Check(limber_actarray_set_trajectory_scale(h_, scale, &t));
        return t;
    }
    /// CMD HOME: homes `joint`, or every joint if negative (the default).
    limber_ticket MoveHome(int32_t joint = -1) {
        limber_ticket t{};
        detail::Check(limber_actarray_home(h_, joint, &t));
        return t;
    }
    /// CMD CURRENT: drives `joint` (every joint if negative) with `current` A.
    limber_ticket SetActuatorCurrent(int32_t joint, double current) {
        limber_ticket t{};
        detail::Check(limber_actarray_set_current(h_, joint, current, &t));
        return t;
    }
    /// CMD MULTI_CURRENT: drives joints 0..n with `currents` A.
    limber_ticket SetActuatorCurrentMulti(const std::vector<double>& currents) {
        limber_ticket t{};
        detail::Check(limber_actarray_set_current_multi(h_, currents.data(), currents.size(), &t));
        return t;
    }
    /// REQ POWER.
    void SetPowerConfig(bool on, Duration timeout = kRequestTimeout) {
        detail::Check(limber_actarray_power(h_, on, detail::Millis(timeout)));
    }
    /// REQ BRAKES.
    void SetBrakesConfig(bool on, Duration timeout = kRequestTimeout) {
        detail::Check(limber_actarray_brakes(h_, on, detail::Millis(timeout)));
    }
    /// REQ SPEED: the speed of `joint` for later position moves.
    void SetSpeedConfig(uint32_t joint, double speed, Duration timeout = kRequestTimeout) {
        detail::Check(limber_actarray_set_speed_config(h_, joint, speed, detail::Millis(timeout)));
    }
    /// REQ ACCEL: the acceleration of `joint` for later position moves.
    void SetAccelerationConfig(uint32_t joint, double accel, Duration timeout = kRequestTimeout) {
        detail::Check(limber_actarray_set_accel_config(h_, joint, accel, detail::Millis(timeout)));
    }
};

/// Player's LimbProxy: a limb, commanded by end-effector poses.
class LimbProxy : public BasicProxy<detail::LimbTraits> {
public:
    using BasicProxy::BasicProxy;
    /// CMD HOME.
    limber_ticket MoveHome() {
        limber_ticket t{};
        detail::Check(limber_limb_home(h_, &t));
        return t;
    }
    /// CMD STOP: stops every joint now.
    limber_ticket Stop() {
        limber_ticket t{};
        detail::Check(limber_limb_stop(h_, &t));
        return t;
    }
    /// CMD SETPOSE: end effector at (px, py, pz), approach vector (ax, ay, az),
    /// orientation vector (ox, oy, oz), in the robot frame (m). Beyond reach: the outcome
    /// is LIMBER_STATUS_OUT_OF_REACH and the state LIMBER_LIMB_STATE_OOR.
    limber_ticket SetPose(double px, double py, double pz, double ax, double ay, double az,
                          double ox, double oy, double oz) {
        limber_ticket t{};
        detail::Check(limber_limb_set_pose(h_, limber_vec3{px, py, pz}, limber_vec3{ax, ay, az},
                                           limber_vec3{ox, oy, oz}, &t));
        return t;
    }
    /// CMD SETPOSE: end effector at `position`, its approach vector along `approach` and
    /// its orientation vector along `orientation` (robot frame, m).
    limber_ticket SetPose(const Vec3& position, const Vec3& approach, const Vec3& orientation) {
        limber_ticket t{};
        detail::Check(limber_limb_set_pose(h_, position, approach, orientation, &t));
        return t;
    }
    /// REQ REACH: where a SETPOSE to this pose would put the end effector and how much it
    /// would adjust the orientation, without moving. A pose the limb cannot reach throws
    /// LIMBER_CODE_REFUSED with its cause in refusal() (LIMBER_STATUS_OUT_OF_REACH, ...).
    limber_limb_reach Reach(const Vec3& position, const Vec3& approach, const Vec3& orientation,
                            Duration timeout = kRequestTimeout) {
        limber_limb_reach r{};
        detail::Check(limber_limb_can_reach(h_, position, approach, orientation,
                                            detail::Millis(timeout), &r));
        return r;
    }
    /// CMD SETPOSITION: end effector at (x, y, z), orientation chosen by the driver.
    limber_ticket SetPosition(double x, double y, double z) {
        limber_ticket t{};
        detail::Check(limber_limb_set_position(h_, limber_vec3{x, y, z}, &t));
        return t;
    }
    /// CMD VECMOVE: moves `length` m along (x, y, z) in a straight line.
    limber_ticket VectorMove(double x, double y, double z, double length) {
        limber_ticket t{};
        detail::Check(limber_limb_vec_move(h_, limber_vec3{x, y, z}, length, &t));
        return t;
    }
    /// CMD LINE: the tool in a straight line to (x, y, z), its orientation kept, at most
    /// `speed` m/s (0: the limb's own); refused before it moves when the line leaves the
    /// reach or hits the world (the state's refused_at says where).
    limber_ticket Line(double x, double y, double z, double speed = 0.0) {
        limber_ticket t{};
        detail::Check(limber_limb_line(h_, limber_vec3{x, y, z}, nullptr, nullptr, speed, &t));
        return t;
    }
    /// CMD LINE: the tool in a straight line to `position`, turned evenly to `approach`
    /// and `orientation`.
    limber_ticket Line(limber_vec3 position, limber_vec3 approach, limber_vec3 orientation,
                       double speed = 0.0) {
        limber_ticket t{};
        detail::Check(limber_limb_line(h_, position, &approach, &orientation, speed, &t));
        return t;
    }
    /// CMD PTP: the joints interpolated to where the tool is at (x, y, z), its orientation
    /// kept, the fastest joint at most `speed` rad/s (0: the joints' own).
    limber_ticket Ptp(double x, double y, double z, double speed = 0.0) {
        limber_ticket t{};
        detail::Check(limber_limb_ptp(h_, limber_vec3{x, y, z}, nullptr, nullptr, speed, &t));
        return t;
    }
    /// CMD PTP to `position` with `approach` and `orientation`.
    limber_ticket Ptp(limber_vec3 position, limber_vec3 approach, limber_vec3 orientation,
                      double speed = 0.0) {
        limber_ticket t{};
        detail::Check(limber_limb_ptp(h_, position, &approach, &orientation, speed, &t));
        return t;
    }
    /// REQ POWER.
    void SetPowerConfig(bool on, Duration timeout = kRequestTimeout) {
        detail::Check(limber_limb_power(h_, on, detail::Millis(timeout)));
    }
    /// REQ BRAKES.
    void SetBrakesConfig(bool on, Duration timeout = kRequestTimeout) {
        detail::Check(limber_limb_brakes(h_, on, detail::Millis(timeout)));
    }
    /// REQ SPEED: the end effector's speed (m/s).
    void SetSpeedConfig(double speed, Duration timeout = kRequestTimeout) {
        detail::Check(limber_limb_set_speed(h_, speed, detail::Millis(timeout)));
    }
};

/// Player's GripperProxy: a gripper.
class GripperProxy : public BasicProxy<detail::GripperTraits> {
public:
    using BasicProxy::BasicProxy;
    /// CMD OPEN.
    limber_ticket Open() { return Send(limber_gripper_open); }
    /// CMD CLOSE.
    limber_ticket Close() { return Send(limber_gripper_close); }
    /// CMD STOP.
    limber_ticket Stop() { return Send(limber_gripper_stop); }
    /// CMD STORE.
    limber_ticket Store() { return Send(limber_gripper_store); }
    /// CMD RETRIEVE.
    limber_ticket Retrieve() { return Send(limber_gripper_retrieve); }
    /// CMD GOAL: the fingers to `gap` m, with at most `effort` N, at `speed` m/s (0: the
    /// gripper's own); WaitDone gives REACHED or STALLED (status OBJECT_PRESENT when the
    /// beams see an object).
    limber_ticket Goal(double gap, double effort = 0.0, double speed = 0.0) {
        limber_ticket t{};
        detail::Check(limber_gripper_goal(h_, gap, effort, speed, &t));
        return t;
    }

private:
    limber_ticket Send(limber_code (*cmd)(limber_gripper*, limber_ticket*)) {
        limber_ticket t{};
        detail::Check(cmd(h_, &t));
        return t;
    }
};

/// A point in a plane, m (Player's player_point_2d_t).
struct Point2d {
    double px;
    double py;
};

/// Player's RangerProxy (and LaserProxy): a range sensor such as a planar laser. Read()
/// takes the latest scan and keeps it; the getters read that scan (Player's proxies read
/// the last scan the client thread received). RequestGeometry() (RequestGeom()) asks for
/// the sensor's pose and configuration, GetPose() returns the pose.
class RangerProxy : public BasicProxy<detail::RangerTraits> {
public:
    using BasicProxy::BasicProxy;
    /// Takes the latest scan (waiting up to `timeout` for a first one) and keeps it.
    const Data& Read(Duration timeout = kStateTimeout) {
        scan_ = GetData(timeout);
        return scan_;
    }
    /// Waits up to `timeout` for a scan newer than the latest one taken, and keeps it.
    const Data& ReadNext(Duration timeout) {
        scan_ = WaitForData(timeout);
        return scan_;
    }
    /// The scan kept by the last Read().
    const Data& GetScan() const noexcept { return scan_; }
    /// REQ GET_GEOM (Player's name for RequestGeometry()).
    const Geom& RequestGeom(Duration timeout = kRequestTimeout) { return RequestGeometry(timeout); }
    /// The sensor's pose on the robot (from the last RequestGeom()).
    limber_pose3 GetPose() const noexcept { return GetGeom().pose; }
    /// Ranges in the kept scan.
    uint32_t GetCount() const noexcept { return scan_.ranges_count; }
    /// Range `i` of the kept scan, m (throws LIMBER_CODE_INVALID_VALUE beyond the count).
    double GetRange(uint32_t i) const {
        Bearing(i);
        return scan_.ranges[i];
    }
    /// Range `i` of the kept scan, m.
    double operator[](uint32_t i) const { return GetRange(i); }
    /// The bearing of range `i`, rad, in the sensor's frame.
    double GetBearing(uint32_t i) const { return Bearing(i); }
    /// The point range `i` hit, in the sensor's frame, m.
    Point2d GetPoint(uint32_t i) const {
        Point2d p{};
        detail::Check(limber_ranger_point(&scan_, i, nullptr, &p.px, &p.py));
        return p;
    }
    /// Bearing of the first range, rad.
    double GetMinAngle() const noexcept { return scan_.min_angle; }
    /// Bearing of the last range, rad.
    double GetMaxAngle() const noexcept { return scan_.max_angle; }
    /// Angle between two ranges, rad (Player's LaserProxy::GetScanRes).
    double GetScanRes() const noexcept { return scan_.angular_res; }
    /// Longest range, m.
    double GetMaxRange() const noexcept { return scan_.max_range; }

private:
    double Bearing(uint32_t i) const {
        double b = 0.0;
        detail::Check(limber_ranger_point(&scan_, i, &b, nullptr, nullptr));
        return b;
    }
    Data scan_{};
};

/// Player's name for a planar laser's proxy.
using LaserProxy = RangerProxy;

/// A proxy's control lease for the lifetime of this object: acquired in the constructor
/// (throws as Acquire()), released in the destructor, which cannot throw: a failure there
/// is left to the driver, which frees the lease when its heartbeat runs out; call
/// Release() to see it. Keep the lease with KeepLease() in the control loop.
///
///     limber::Lease lease(arm, "picker", std::chrono::milliseconds(500));
template <class T>
class Lease {
public:
    Lease(BasicProxy<T>& proxy, const std::string& name, Duration heartbeat) : proxy_(&proxy) {
        proxy.Acquire(name, heartbeat);
    }
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    Lease(Lease&& o) noexcept : proxy_(std::exchange(o.proxy_, nullptr)) {}
    Lease& operator=(Lease&&) = delete;
    ~Lease() {
        if (proxy_ != nullptr) T::release_lease(proxy_->get());
    }
    /// Renews the lease when a third of its heartbeat has passed; whether it did.
    bool KeepLease() { return proxy_->KeepLease(); }
    /// Gives the lease back now, throwing on failure (the destructor then does nothing).
    void Release() {
        if (proxy_ != nullptr) std::exchange(proxy_, nullptr)->Release();
    }

private:
    BasicProxy<T>* proxy_;
};

}  // namespace limber

#endif /* LIMBER_HPP */
