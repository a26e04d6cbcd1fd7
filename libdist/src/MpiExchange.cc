/// @file   MpiExchange.cc
/// @brief  Particle migration, halo copies and reductions over MPI (see the header).
#include "ghostfx/dist/MpiExchange.h"

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <unordered_map>

namespace ghostfx {
namespace dist {

using namespace sph;

namespace {

void check(int code, const char* what)
{
    if (code != MPI_SUCCESS) {
        char text[MPI_MAX_ERROR_STRING];
        int length = 0;
        MPI_Error_string(code, text, &length);
        throw Error(msg("MPI: ", what, " failed: ", std::string(text, std::size_t(length))));
    }
}

// Byte packing of particle rows ----------------------------------------------------------------

class Writer
{
public:
    explicit Writer(std::vector<char>& out) : mOut(out) {}
    template <typename T>
    void put(const T& value)
    {
        const std::size_t at = mOut.size();
        mOut.resize(at + sizeof(T));
        std::memcpy(mOut.data() + at, &value, sizeof(T));
    }
    void put(const std::string& s)
    {
        put(std::uint32_t(s.size()));
        mOut.insert(mOut.end(), s.begin(), s.end());
    }

private:
    std::vector<char>& mOut;
};

class Reader
{
public:
    explicit Reader(const std::vector<char>& in) : mIn(in) {}
    template <typename T>
    T get()
    {
        if (mAt + sizeof(T) > mIn.size()) throw Error("MPI exchange: message ends early");
        T value;
        std::memcpy(&value, mIn.data() + mAt, sizeof(T));
        mAt += sizeof(T);
        return value;
    }
    std::string getString()
    {
        const std::uint32_t n = get<std::uint32_t>();
        if (mAt + n > mIn.size()) throw Error("MPI exchange: message ends early");
        std::string s(mIn.data() + mAt, n);
        mAt += n;
        return s;
    }
    bool done() const { return mAt == mIn.size(); }

private:
    const std::vector<char>& mIn;
    std::size_t mAt = 0;
};

/// The channels `names`, each as its name and its values at `rows` (`channel(name)` points to a
/// channel's values), after their count.
template <typename Channel>
void packChannels(Writer& w, const std::vector<std::string>& names, const std::vector<Index>& rows,
                  Channel&& channel)
{
    w.put(std::uint32_t(names.size()));
    for (const std::string& name : names) {
        w.put(name);
        const auto& data = *channel(name);
        for (Index i : rows) w.put(data[i]);
    }
}

/// The channels packChannels wrote, each added by `add(name)` (which points to its values) and
/// filled with `n` values of type T.
template <typename T, typename Add>
void unpackChannels(Reader& r, std::size_t n, Add&& add)
{
    const std::uint32_t count = r.get<std::uint32_t>();
    for (std::uint32_t c = 0; c < count; ++c) {
        auto& data = *add(r.getString());
        for (std::size_t k = 0; k < n; ++k) data[k] = r.get<T>();
    }
}

/// Rows of `set` with every channel, by name, so the receiver needs no agreement on layout.
void packRows(const ParticleSet& set, const std::vector<Index>& rows, std::vector<char>& out)
{
    Writer w(out);
    w.put(std::uint64_t(rows.size()));
    for (Index i : rows) {
        w.put(set.positions()[i]);
        w.put(set.velocities()[i]);
        w.put(set.masses()[i]);
        w.put(set.densities()[i]);
        w.put(set.pressures()[i]);
        w.put(std::uint8_t(set.kinds()[i]));
        w.put(set.ids()[i]);
    }
    packChannels(w, set.scalarChannelNames(), rows,
                 [&](const std::string& name) { return &set.scalarChannel(name); });
    packChannels(w, set.vectorChannelNames(), rows,
                 [&](const std::string& name) { return &set.vectorChannel(name); });
}

/// The rows of one message as a particle set (ids as sent).
ParticleSet unpackRows(const std::vector<char>& in)
{
    ParticleSet out;
    if (in.empty()) return out;
    Reader r(in);
    const std::size_t n = std::size_t(r.get<std::uint64_t>());
    std::vector<Vec3> x(n), v(n);
    std::vector<Real> m(n), rho(n), p(n);
    std::vector<ParticleKind> kind(n);
    std::vector<ParticleId> id(n);
    for (std::size_t k = 0; k < n; ++k) {
        x[k] = r.get<Vec3>();
        v[k] = r.get<Vec3>();
        m[k] = r.get<Real>();
        rho[k] = r.get<Real>();
        p[k] = r.get<Real>();
        kind[k] = ParticleKind(r.get<std::uint8_t>());
        id[k] = r.get<ParticleId>();
    }
    out.addBatch(x, Real(0), ParticleKind::Liquid);
    out.velocities() = v;
    out.masses() = m;
    out.densities() = rho;
    out.pressures() = p;
    out.kinds() = kind;
    out.ids() = id;
    unpackChannels<Real>(r, n,
                         [&](const std::string& name) { return &out.addScalarChannel(name); });
    unpackChannels<Vec3>(r, n,
                         [&](const std::string& name) { return &out.addVectorChannel(name); });
    if (!r.done()) throw Error("MPI exchange: message longer than its particles");
    // A set's counter stays above every id it holds, particles from other ranks included
    // (ParticleSet::append then lifts the receiver's counter on its own sequence).
    if (!id.empty()) out.setNextId(*std::max_element(id.begin(), id.end()) + 1);
    return out;
}

/// A channel's values as Reals: 1 per particle (scalars) or 3 (vectors).
struct ChannelView
{
    Real* scalar = nullptr;
    Vec3* vector = nullptr;
};

ChannelView view(ParticleSet& set, const std::string& name)
{
    if (name == "velocity") return {nullptr, set.velocities().data()};
    if (name == "density") return {set.densities().data(), nullptr};
    if (name == "pressure") return {set.pressures().data(), nullptr};
    if (name == "mass") return {set.masses().data(), nullptr};
    if (set.hasScalarChannel(name)) return {set.scalarChannel(name).data(), nullptr};
    if (set.hasVectorChannel(name)) return {nullptr, set.vectorChannel(name).data()};
    throw ValueError(msg("MPI exchange: refresh of '", name, "': no such channel"));
}

} // namespace

// Session --------------------------------------------------------------------------------------

MpiSession::MpiSession(int* argc, char*** argv)
{
    int ready = 0;
    MPI_Initialized(&ready);
    if (!ready) {
        check(MPI_Init(argc, argv), "MPI_Init");
        mOwner = true;
    }
    // Errors come back as codes (thrown as ghostfx errors), not as aborts.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
}

MpiSession::~MpiSession()
{
    if (mOwner) MPI_Finalize();
}

int MpiSession::rank() const
{
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

int MpiSession::ranks() const
{
    int n = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &n);
    return n;
}

int launcherRankCount()
{
    // Open MPI's mpirun, then the PMI launchers (MPICH's and Intel's mpiexec, srun
    // --mpi=pmi2), then a task of a Slurm job step (srun --mpi=pmix sets no size of its own;
    // SLURM_STEP_NUM_TASKS belongs to the step, not to the batch script that sbatch runs, and
    // SLURM_PROCID only to a task srun started). A wrong guess costs nothing worse than
    // MPI_Init: a run whose MPI world has one process runs as one.
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
        if (const char* value = std::getenv(name)) {
            const int n = std::atoi(value);
            if (n > 0) return n;
        }
    }
    if (std::getenv("SLURM_PROCID")) {
        if (const char* value = std::getenv("SLURM_STEP_NUM_TASKS")) {
            const int n = std::atoi(value);
            if (n > 0) return n;
        }
    }
    return 1;
}

// Exchange -------------------------------------------------------------------------------------

MpiExchange::MpiExchange(MPI_Comm comm, const std::vector<Vec3>& points, DecompositionScheme scheme)
    : mComm(comm)
    , mScheme(scheme)
{
    check(MPI_Comm_rank(comm, &mRank), "MPI_Comm_rank");
    check(MPI_Comm_size(comm, &mRanks), "MPI_Comm_size");
    mParts = DomainDecomposition::balanced(points, mRanks, scheme);
    mSent.resize(static_cast<std::size_t>(mRanks));
    mReceived.resize(static_cast<std::size_t>(mRanks));
}

MpiExchange::MpiExchange(MPI_Comm comm, DomainDecomposition parts, DecompositionScheme scheme)
    : mComm(comm)
    , mParts(std::move(parts))
    , mScheme(scheme)
{
    check(MPI_Comm_rank(comm, &mRank), "MPI_Comm_rank");
    check(MPI_Comm_size(comm, &mRanks), "MPI_Comm_size");
    if (mParts.parts() != mRanks) {
        throw ValueError(msg("MPI exchange: ", mParts.parts(), " parts for ", mRanks, " ranks"));
    }
    mSent.resize(std::size_t(mRanks));
    mReceived.resize(std::size_t(mRanks));
}

std::vector<std::vector<char>> MpiExchange::allToAll(
    const std::vector<std::vector<char>>& bytes) const
{
    const std::size_t n = std::size_t(mRanks);
    std::vector<long long> sendCounts(n), receiveCounts(n);
    for (std::size_t q = 0; q < n; ++q) sendCounts[q] = (long long)bytes[q].size();
    check(MPI_Alltoall(sendCounts.data(), 1, MPI_LONG_LONG, receiveCounts.data(), 1, MPI_LONG_LONG,
                       mComm),
          "MPI_Alltoall (counts)");
    std::vector<int> sc(n), sd(n), rc(n), rd(n);
    std::vector<char> send, receive;
    long long sendTotal = 0, receiveTotal = 0;
    for (std::size_t q = 0; q < n; ++q) {
        sd[q] = int(sendTotal);
        rd[q] = int(receiveTotal);
        sc[q] = int(sendCounts[q]);
        rc[q] = int(receiveCounts[q]);
        sendTotal += sendCounts[q];
        receiveTotal += receiveCounts[q];
    }
    if (sendTotal > std::numeric_limits<int>::max()
        || receiveTotal > std::numeric_limits<int>::max())
        throw Error("MPI exchange: more than 2 GB in one exchange (use more ranks)");
    send.reserve(std::size_t(sendTotal));
    for (const auto& b : bytes) send.insert(send.end(), b.begin(), b.end());
    receive.resize(std::size_t(receiveTotal));
    check(MPI_Alltoallv(send.data(), sc.data(), sd.data(), MPI_BYTE, receive.data(), rc.data(),
                        rd.data(), MPI_BYTE, mComm),
          "MPI_Alltoallv");
    std::vector<std::vector<char>> out(n);
    for (std::size_t q = 0; q < n; ++q)
        out[q].assign(receive.begin() + rd[q], receive.begin() + rd[q] + rc[q]);
    return out;
}

void MpiExchange::dropHalo(ParticleSet& set)
{
    if (!set.hasScalarChannel(HALO_CHANNEL)) return;
    const auto& halo = set.scalarChannel(HALO_CHANNEL);
    std::vector<std::uint8_t> remove(set.size(), 0);
    bool any = false;
    for (std::size_t i = 0; i < remove.size(); ++i) any |= (remove[i] = halo[i] != Real(0)) != 0;
    if (any) set.removeIf(remove);
}

void MpiExchange::migrate(ParticleSet& set)
{
    std::vector<std::vector<Index>> rows(static_cast<std::size_t>(mRanks));
    std::vector<std::uint8_t> leaving(set.size(), 0);
    for (std::size_t i = 0; i < set.size(); ++i) {
        const int owner = mParts.owner(set.positions()[i]);
        if (owner == mRank) continue;
        rows[std::size_t(owner)].push_back(Index(i));
        leaving[i] = 1;
    }
    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(mRanks));
    for (int q = 0; q < mRanks; ++q) {
        if (!rows[std::size_t(q)].empty())
            packRows(set, rows[std::size_t(q)], bytes[std::size_t(q)]);
        mMigrated += rows[std::size_t(q)].size();
    }
    set.removeIf(leaving);
    for (const auto& message : allToAll(bytes)) {
        if (!message.empty()) set.append(unpackRows(message));
    }
}

void MpiExchange::rebalanceIfNeeded(ParticleSet& set)
{
    const double owned = double(set.size());
    const double largest = maxOf(owned), total = sumOf(owned);
    if (!(total > 0) || largest * mRanks / total <= mRebalanceAbove) return;
    // Every rank's positions to every rank, then the same cuts everywhere.
    const std::vector<Vec3> points = allPositions(set.positions());
    mParts = DomainDecomposition::balanced(points, mRanks, mScheme);
    ++mRebalances;
}

void MpiExchange::exchange(ParticleSet& set, Real width)
{
    dropHalo(set);
    if (!set.hasScalarChannel(HALO_CHANNEL)) set.addScalarChannel(HALO_CHANNEL, Real(0));
    rebalanceIfNeeded(set);
    migrate(set);

    // Halo copies: this rank's particles within `width` of another rank's region.
    std::vector<std::vector<Index>> rows(static_cast<std::size_t>(mRanks));
    for (auto& ids : mSent) ids.clear();
    for (std::size_t i = 0; i < set.size(); ++i) {
        mParts.forEachHaloPart(set.positions()[i], width, [&](int q) {
            rows[std::size_t(q)].push_back(Index(i));
            mSent[std::size_t(q)].push_back(set.ids()[i]);
        });
    }
    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(mRanks));
    for (int q = 0; q < mRanks; ++q) {
        if (!rows[std::size_t(q)].empty())
            packRows(set, rows[std::size_t(q)], bytes[std::size_t(q)]);
    }
    const std::vector<std::vector<char>> received = allToAll(bytes);
    for (int q = 0; q < mRanks; ++q) {
        auto& ids = mReceived[std::size_t(q)];
        ids.clear();
        if (received[std::size_t(q)].empty()) continue;
        ParticleSet copies = unpackRows(received[std::size_t(q)]);
        auto& flag = copies.addScalarChannel(HALO_CHANNEL);
        std::fill(flag.begin(), flag.end(), Real(1));
        ids = copies.ids();
        mHaloReceived += copies.size();
        set.append(copies);
    }
    // The ids every refresh until the next exchange looks for: sent (owned here) and received
    // (halo copies here). An owned particle sent to several ranks is one key.
    mWhere.clear();
    for (const auto* lists : {&mSent, &mReceived})
        for (const auto& ids : *lists)
            for (ParticleId id : ids) mWhere.emplace(id, INVALID_INDEX);
}

void MpiExchange::refresh(ParticleSet& set, const std::vector<std::string>& channels)
{
    // Where the sent and received ids are now (the solver may have reordered the set since
    // the exchange): one pass over the set, looking up only the ids of the last exchange.
    const auto& halo = set.scalarChannel(HALO_CHANNEL);
    for (auto& entry : mWhere) entry.second = INVALID_INDEX;
    for (std::size_t i = 0; i < set.size(); ++i) {
        const auto it = mWhere.find(set.ids()[i]);
        if (it != mWhere.end()) it->second = Index(i);
    }
    const auto find = [&](ParticleId id, bool copy) {
        const auto it = mWhere.find(id);
        if (it == mWhere.end() || it->second == INVALID_INDEX) return INVALID_INDEX;
        return (halo[it->second] != Real(0)) == copy ? it->second : INVALID_INDEX;
    };
    std::vector<ChannelView> views;
    for (const std::string& name : channels) views.push_back(view(set, name));

    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(mRanks));
    for (int q = 0; q < mRanks; ++q) {
        Writer w(bytes[std::size_t(q)]);
        for (ParticleId id : mSent[std::size_t(q)]) {
            const Index i = find(id, false);
            if (i == INVALID_INDEX)
                throw Error(msg("MPI exchange: particle id ", id, " sent to rank ", q,
                                " is gone from rank ", mRank, " before its refresh"));
            for (const ChannelView& c : views) {
                if (c.scalar) w.put(c.scalar[i]);
                else w.put(c.vector[i]);
            }
        }
    }
    const std::vector<std::vector<char>> received = allToAll(bytes);
    for (int q = 0; q < mRanks; ++q) {
        if (mReceived[std::size_t(q)].empty()) continue;
        Reader r(received[std::size_t(q)]);
        for (ParticleId id : mReceived[std::size_t(q)]) {
            const Index i = find(id, true);
            // A copy this rank removed since (the kill box) still has its values in the message.
            for (const ChannelView& c : views) {
                if (c.scalar) {
                    const Real value = r.get<Real>();
                    if (i != INVALID_INDEX) c.scalar[i] = value;
                } else {
                    const Vec3 value = r.get<Vec3>();
                    if (i != INVALID_INDEX) c.vector[i] = value;
                }
            }
        }
        if (!r.done()) throw Error("MPI exchange: refresh message longer than its copies");
    }
}

ParticleSet MpiExchange::gather(const ParticleSet& set, const std::vector<ParticleKind>& kinds,
                                int root) const
{
    const std::vector<Real>* halo =
        set.hasScalarChannel(HALO_CHANNEL) ? &set.scalarChannel(HALO_CHANNEL) : nullptr;
    std::vector<Index> rows;
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo && (*halo)[i] != Real(0)) continue;
        if (std::find(kinds.begin(), kinds.end(), set.kinds()[i]) != kinds.end())
            rows.push_back(Index(i));
    }
    std::vector<char> bytes;
    packRows(set, rows, bytes);
    const int n = int(bytes.size());
    std::vector<int> counts(static_cast<std::size_t>(mRanks)), displs(counts.size());
    check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, mComm), "MPI_Gather");
    long long total = 0;
    for (std::size_t q = 0; q < counts.size(); ++q) {
        displs[q] = int(total);
        total += counts[q];
    }
    if (total > std::numeric_limits<int>::max())
        throw Error("MPI gather: more than 2 GB of particles for one rank");
    std::vector<char> all(mRank == root ? std::size_t(total) : 0);
    check(MPI_Gatherv(bytes.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE,
                      root, mComm),
          "MPI_Gatherv");
    ParticleSet out;
    if (mRank != root) return out;
    for (std::size_t q = 0; q < counts.size(); ++q) {
        const std::vector<char> part(all.begin() + displs[q], all.begin() + displs[q] + counts[q]);
        ParticleSet rowsOf = unpackRows(part);
        if (rowsOf.hasScalarChannel(HALO_CHANNEL)) rowsOf.removeChannel(HALO_CHANNEL);
        out.append(rowsOf);
    }
    return out;
}

ParticleSet MpiExchange::surroundings(const ParticleSet& set,
                                      const std::vector<ParticleKind>& kinds, Real width,
                                      std::size_t* own) const
{
    const std::vector<Real>* halo =
        set.hasScalarChannel(HALO_CHANNEL) ? &set.scalarChannel(HALO_CHANNEL) : nullptr;
    std::vector<Index> mine;
    std::vector<std::vector<Index>> rows(static_cast<std::size_t>(mRanks));
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo && (*halo)[i] != Real(0)) continue;
        if (std::find(kinds.begin(), kinds.end(), set.kinds()[i]) == kinds.end()) continue;
        mine.push_back(Index(i));
        // A particle that moved into another region since the last exchange is still this
        // rank's; forEachHaloPart leaves out the region it lies in, so that one is added here.
        const int at = mParts.owner(set.positions()[i]);
        if (at != mRank) rows[std::size_t(at)].push_back(Index(i));
        mParts.forEachHaloPart(set.positions()[i], width, [&](int q) {
            if (q != mRank) rows[std::size_t(q)].push_back(Index(i));
        });
    }
    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(mRanks));
    for (int q = 0; q < mRanks; ++q) {
        if (!rows[std::size_t(q)].empty())
            packRows(set, rows[std::size_t(q)], bytes[std::size_t(q)]);
    }
    const std::vector<std::vector<char>> received = allToAll(bytes);
    std::vector<char> ownBytes;
    packRows(set, mine, ownBytes);
    ParticleSet out = unpackRows(ownBytes);
    if (own) *own = out.size();
    for (const auto& message : received) {
        if (!message.empty()) out.append(unpackRows(message));
    }
    if (out.hasScalarChannel(HALO_CHANNEL)) out.removeChannel(HALO_CHANNEL);
    return out;
}

ParticleSet MpiExchange::redistribute(const ParticleSet& set,
                                      const std::vector<ParticleKind>& kinds,
                                      const std::function<int(const Vec3&)>& destination,
                                      std::size_t* sent) const
{
    const std::vector<Real>* halo =
        set.hasScalarChannel(HALO_CHANNEL) ? &set.scalarChannel(HALO_CHANNEL) : nullptr;
    std::vector<std::vector<Index>> rows(static_cast<std::size_t>(mRanks));
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo && (*halo)[i] != Real(0)) continue;
        if (std::find(kinds.begin(), kinds.end(), set.kinds()[i]) == kinds.end()) continue;
        const int q = destination(set.positions()[i]);
        if (q < 0 || q >= mRanks)
            throw Error(msg("MPI redistribute: destination rank ", q, " of ", mRanks));
        rows[std::size_t(q)].push_back(Index(i));
    }
    std::vector<std::vector<char>> bytes(static_cast<std::size_t>(mRanks));
    std::size_t away = 0;
    for (int q = 0; q < mRanks; ++q) {
        if (q == mRank || rows[std::size_t(q)].empty()) continue;
        packRows(set, rows[std::size_t(q)], bytes[std::size_t(q)]);
        away += rows[std::size_t(q)].size();
    }
    if (sent) *sent = away;
    const std::vector<std::vector<char>> received = allToAll(bytes);
    std::vector<char> ownBytes;
    packRows(set, rows[std::size_t(mRank)], ownBytes);
    ParticleSet out = unpackRows(ownBytes);
    for (const auto& message : received) {
        if (!message.empty()) out.append(unpackRows(message));
    }
    if (out.hasScalarChannel(HALO_CHANNEL)) out.removeChannel(HALO_CHANNEL);
    return out;
}

void MpiExchange::collect(const std::string& mine,
                          const std::function<void(int, const std::string&)>& fn, int root) const
{
    constexpr int SIZE_TAG = 7101, BYTES_TAG = 7102;
    if (mine.size() > std::size_t(std::numeric_limits<int>::max()))
        throw Error(msg("MPI collect: ", mine.size(), " bytes from one rank (at most 2 GB)"));
    if (mRank != root) {
        const long long n = (long long)mine.size();
        check(MPI_Send(&n, 1, MPI_LONG_LONG, root, SIZE_TAG, mComm), "MPI_Send (size)");
        check(MPI_Send(mine.data(), int(n), MPI_BYTE, root, BYTES_TAG, mComm), "MPI_Send");
        return;
    }
    fn(mRank, mine);
    std::string theirs;
    for (int q = 0; q < mRanks; ++q) {
        if (q == root) continue;
        long long n = 0;
        check(MPI_Recv(&n, 1, MPI_LONG_LONG, q, SIZE_TAG, mComm, MPI_STATUS_IGNORE),
              "MPI_Recv (size)");
        theirs.assign(std::size_t(n), '\0');
        check(MPI_Recv(theirs.data(), int(n), MPI_BYTE, q, BYTES_TAG, mComm, MPI_STATUS_IGNORE),
              "MPI_Recv");
        fn(q, theirs);
    }
}

std::vector<Vec3> MpiExchange::allPositions(const std::vector<Vec3>& mine)
{
    const int n = int(mine.size() * 3);
    std::vector<int> counts(static_cast<std::size_t>(mRanks)), displs(counts.size());
    check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, mComm), "MPI_Allgather");
    long long sum = 0;
    for (int q = 0; q < mRanks; ++q) {
        displs[std::size_t(q)] = int(sum);
        sum += counts[std::size_t(q)];
    }
    if (sum > std::numeric_limits<int>::max())
        throw Error("MPI all-gather: more than 2^31 coordinates");
    std::vector<Real> flat(static_cast<std::size_t>(n)), all(static_cast<std::size_t>(sum));
    for (std::size_t i = 0; i < mine.size(); ++i)
        for (int a = 0; a < 3; ++a) flat[3 * i + std::size_t(a)] = mine[i][a];
    const MPI_Datatype real = sizeof(Real) == sizeof(double) ? MPI_DOUBLE : MPI_FLOAT;
    check(
        MPI_Allgatherv(flat.data(), n, real, all.data(), counts.data(), displs.data(), real, mComm),
        "MPI_Allgatherv");
    std::vector<Vec3> out(all.size() / 3);
    for (std::size_t k = 0; k < out.size(); ++k)
        out[k] = Vec3(all[3 * k], all[3 * k + 1], all[3 * k + 2]);
    return out;
}

double MpiExchange::maxOf(double value)
{
    double out = value;
    check(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, mComm), "MPI_Allreduce (max)");
    return out;
}

double MpiExchange::minOf(double value)
{
    double out = value;
    check(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MIN, mComm), "MPI_Allreduce (min)");
    return out;
}

double MpiExchange::sumOf(double value)
{
    double out = value;
    check(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_SUM, mComm), "MPI_Allreduce (sum)");
    return out;
}

} // namespace dist
} // namespace ghostfx
