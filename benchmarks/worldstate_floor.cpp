// The floor of a full-state read through libsumo's API: the same getters the Python reader
// calls (id lists; position, angle, speed, acceleration, lane per vehicle; the same less
// acceleration per person), called from C++ with no Python, against eclipse-sumo's libsumocpp.
// Bare and read blocks of 10 steps alternate in one simulation (reads do not change it), so
// both see the same traffic and machine load; costs are process CPU time.
// Built and run by benchmarks/worldstate.py: worldstate_floor NET ROUTES WARM_S MEASURE_S
#include <libsumo/libsumo.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

namespace {

double cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

// Returns a checksum so that the compiler cannot drop the reads.
double read_all() {
    double sum = 0.0;
    for (const std::string& v : libsumo::Vehicle::getIDList()) {
        const libsumo::TraCIPosition p = libsumo::Vehicle::getPosition3D(v);
        sum += p.x + p.y + p.z + libsumo::Vehicle::getAngle(v) + libsumo::Vehicle::getSpeed(v);
        sum += libsumo::Vehicle::getAcceleration(v) + libsumo::Vehicle::getLaneID(v).size();
    }
    for (const std::string& q : libsumo::Person::getIDList()) {
        const libsumo::TraCIPosition p = libsumo::Person::getPosition3D(q);
        sum += p.x + p.y + p.z + libsumo::Person::getAngle(q) + libsumo::Person::getSpeed(q);
        sum += libsumo::Person::getLaneID(q).size();
    }
    return sum;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 5) {
        std::fprintf(stderr, "usage: %s NET ROUTES WARM_S MEASURE_S\n", argv[0]);
        return 2;
    }
    const double warm = std::stod(argv[3]);
    const double measure = std::stod(argv[4]);
    libsumo::Simulation::start({"sumo", "-n", argv[1], "-r", argv[2], "--step-length", "0.1",
                                "--seed", "1", "--no-step-log", "true", "--no-warnings", "true",
                                "--collision.action", "warn", "--collision.check-junctions",
                                "true", "--collision.mingap-factor", "0", "--time-to-teleport",
                                "-1"});
    libsumo::Simulation::step(warm);
    const int block = 10;
    const int pairs = std::max(1, static_cast<int>(measure / 0.1) / (2 * block));
    double bare = 0.0, read = 0.0, checksum = 0.0;
    std::vector<double> ratios;
    for (int k = 0; k < pairs; ++k) {
        double t0 = cpu_seconds();
        for (int i = 0; i < block; ++i) libsumo::Simulation::step();
        const double b = cpu_seconds() - t0;
        t0 = cpu_seconds();
        for (int i = 0; i < block; ++i) {
            libsumo::Simulation::step();
            checksum += read_all();
        }
        const double r = cpu_seconds() - t0;
        bare += b;
        read += r;
        ratios.push_back(r / b - 1.0);
    }
    const size_t actors = libsumo::Vehicle::getIDCount() + libsumo::Person::getIDCount();
    libsumo::Simulation::close();
    std::sort(ratios.begin(), ratios.end());
    const double steps = static_cast<double>(pairs) * block;
    std::printf("checksum %.6g\n", checksum);
    const size_t n = ratios.size();
    std::printf("%zu actors; bare %.0f, bare + read %.0f steps/CPU-s; cost %+.0f %% (median of "
                "%d paired blocks; IQR %+.0f..%+.0f %%)\n",
                actors, steps / bare, steps / read, 100.0 * ratios[n / 2], pairs,
                100.0 * ratios[n / 4], 100.0 * ratios[3 * n / 4]);
    return 0;
}
