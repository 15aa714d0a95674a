// The streaming pager of a paged city. See region_pager.h.
#include "runtime/scene/region_pager.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "foundation/process_memory.h"
#include "foundation/timing.h"

namespace vista {

namespace {

// 2D distance from `p` to the rectangle [lo, hi].
double pointRect(const glm::dvec2& p, const glm::dvec2& lo, const glm::dvec2& hi) {
    const double dx = std::max({lo.x - p.x, 0.0, p.x - hi.x});
    const double dy = std::max({lo.y - p.y, 0.0, p.y - hi.y});
    return std::sqrt(dx * dx + dy * dy);
}

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

RegionPager::RegionPager(const PagedManifest& manifest, const RegionPagerOptions& options) : _m(manifest), _o(options) {
    VISTA_CHECK(std::isfinite(_o.radius) && _o.radius >= 0);
    VISTA_CHECK(std::isfinite(_o.far) && _o.far >= 0);
    VISTA_CHECK(std::isfinite(_o.prefetchS) && _o.prefetchS >= 0);
    VISTA_CHECK(_o.workers >= 1 && _o.workers <= 16);
    const size_t n = _m.regions.size();
    VISTA_CHECK(std::isfinite(_o.chunkRadius));
    for (double w : {_o.cost.full, _o.cost.coarse, _o.cost.chunks}) VISTA_CHECK(std::isfinite(w) && w > 0);
    VISTA_CHECK(std::isfinite(_o.cost.loading) && _o.cost.loading >= 0);
    for (auto* v : {&_desired, &_nearEye, &_holdFull, &_holdCoarse, &_flightFull, &_flightCoarse, &_failedFull,
                    &_failedCoarse, &_desiredChunks, &_nearEyeChunks, &_holdChunks, &_flightChunks})
        v->assign(n, 0);
    _key.assign(n, 0.0);
    // What a load passes through while a worker decodes and prepares it, beyond what it keeps:
    // room held back from the budget for each worker's largest possible load.
    uint64_t largest = 0;
    for (const PagedRegionEntry& r : _m.regions)
        if (!r.empty) largest = std::max(largest, r.bytes);
    _reserve = uint64_t(std::llround(double(largest) * _o.cost.loading)) * uint64_t(_o.workers);
    setBudget(_o.budgetBytes);
    for (int k = 0; k < _o.workers; ++k) _threads.emplace_back([this] { workerLoop(); });
}

RegionPager::~RegionPager() {
    {
        std::lock_guard<std::mutex> lock(_mutex);
        _stop = true;
        _queue.clear();
    }
    _work.notify_all();
    for (std::thread& t : _threads) t.join();
}

void RegionPager::workerLoop() {
    std::unique_lock<std::mutex> lock(_mutex);
    for (;;) {
        _work.wait(lock, [this] { return _stop || !_queue.empty(); });
        if (_stop) return;
        const Job job = _queue.front();
        _queue.pop_front();
        ++_busy;
        lock.unlock();
        Done done;
        done.job = job;
        const auto start = std::chrono::steady_clock::now();
        done.model = loadPagedRegion(_m, job.region, job.coarse);
        if (done.model && _o.prepare) {
            RegionLoad load;
            load.region = job.region;
            load.coarse = job.coarse;
            load.level = !job.chunks;
            load.chunks = job.chunks || _o.chunkRadius < 0;
            done.prepared = _o.prepare(*done.model, load);
        }
        // Under a budget, the heap's free pages (this load's decoding, the levels dropped since)
        // go back to the system: glibc keeps them resident otherwise, and a drive's resident set
        // would settle far above what it holds (measured: 2.4 against 1.3 GB at the end of a
        // 30-minute drive under 2 GB). On the worker, so no frame waits for it.
        if (_o.budgetBytes > 0) releaseFreeMemory();
        done.loader = std::this_thread::get_id();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        lock.lock();
        if (!job.coarse && !job.chunks && done.model) {
            _fullLoadS.push_back(seconds);
            if (_fullLoadS.size() > size_t(kLoadTimesKept)) _fullLoadS.pop_front();
            _fullLoadSMax = std::max(_fullLoadSMax, seconds);
        }
        --_busy;
        done.sequence = ++_finished;
        _done.push_back(std::move(done));
        _arrived.notify_all();
    }
}

uint64_t RegionPager::levelBytes(int region, bool coarse) const {
    const PagedRegionEntry& r = _m.regions[size_t(region)];
    return coarse ? r.coarseBytes : r.bytes;
}

uint64_t RegionPager::cost(int region, bool coarse, bool chunks) const {
    const double w = chunks ? _o.cost.chunks : (coarse ? _o.cost.coarse : _o.cost.full);
    return uint64_t(std::llround(double(levelBytes(region, coarse)) * w));
}

void RegionPager::computeDesired() {
    const double farM = _o.far > _o.radius ? _o.far : -1.0;
    uint64_t total = 0;
    // Under a budget the chunk parts of the full regions in the band are reserved before any
    // level is cut: the near field around the camera outranks the far city.
    uint64_t reserved = 0;
    std::vector<uint64_t> partCost(_m.regions.size(), 0);
    for (size_t i = 0; i < _m.regions.size(); ++i) {
        const PagedRegionEntry& r = _m.regions[i];
        _desired[i] = kNone;
        _nearEye[i] = 0;
        if (r.empty) continue;
        const glm::dvec2 lo(r.lo), hi(r.hi);
        const double dEye = pointRect(_eye, lo, hi);
        const double d = reachDistance(dEye);
        _key[i] = 0.5 * (dEye + pointRect(_ahead, lo, hi));
        uint8_t level = d <= _o.radius ? kFull : (d <= farM ? kCoarse : kNone);
        if (level == kFull && _failedFull[i]) level = kCoarse;
        if (level == kCoarse && _failedCoarse[i]) level = kNone;
        _desired[i] = level;
        _nearEye[i] = level == kFull ? dEye <= _o.radius : (level == kCoarse && dEye <= farM);
        if (level != kNone) total += cost(int(i), level == kCoarse);
        if (level == kFull && _o.chunkRadius >= 0 && d <= _o.chunkRadius) {
            partCost[i] = cost(int(i), false, true);
            reserved += partCost[i];
        }
    }
    if (_o.budgetBytes == 0 || total + reserved <= _budget) {
        computeChunks(total);
        return;
    }
    total += reserved;
    // Over the budget: coarse levels go first, farthest first; then full
    // regions, farthest first (the radius shrinks), each keeping its coarse
    // level when that fits; then regions left out get their coarse level
    // back, nearest first, while it fits.
    ++_stats.budgetLimited;
    auto byKey = [&](uint8_t level) {
        std::vector<int> list;
        for (size_t i = 0; i < _desired.size(); ++i)
            if (_desired[i] == level) list.push_back(int(i));
        std::sort(list.begin(), list.end(), [&](int x, int y) {
            return _key[size_t(x)] != _key[size_t(y)] ? _key[size_t(x)] < _key[size_t(y)] : x < y;
        });
        return list;  // nearest first
    };
    std::vector<int> coarse = byKey(kCoarse), full = byKey(kFull), out;
    while (total > _budget) {
        if (!coarse.empty()) {
            const int i = coarse.back();
            coarse.pop_back();
            total -= cost(i, true);
            _desired[size_t(i)] = kNone;
            out.push_back(i);
        } else if (!full.empty()) {
            const int i = full.back();
            full.pop_back();
            total -= cost(i, false) + partCost[size_t(i)];
            reserved -= partCost[size_t(i)];
            _desired[size_t(i)] = kNone;
            if (!_failedCoarse[size_t(i)]) {
                _desired[size_t(i)] = kCoarse;
                total += cost(i, true);
                coarse.push_back(i);
            } else {
                out.push_back(i);
            }
        } else {
            break;
        }
    }
    std::sort(out.begin(), out.end(), [&](int x, int y) {
        return _key[size_t(x)] != _key[size_t(y)] ? _key[size_t(x)] < _key[size_t(y)] : x < y;
    });
    for (int i : out)
        if (!_failedCoarse[size_t(i)] && total + cost(i, true) <= _budget) {
            _desired[size_t(i)] = kCoarse;
            total += cost(i, true);
        }
    for (size_t i = 0; i < _desired.size(); ++i)
        if (_desired[i] == kNone) _nearEye[i] = 0;
    computeChunks(total - reserved);
}

// The chunk parts wanted: the full regions within chunkRadius of the lookahead's reach, nearest
// first while the budget (after every level: `total`, their cost) has room.
void RegionPager::computeChunks(uint64_t total) {
    std::fill(_desiredChunks.begin(), _desiredChunks.end(), 0);
    std::fill(_nearEyeChunks.begin(), _nearEyeChunks.end(), 0);
    if (_o.chunkRadius < 0) return;
    std::vector<int> band;
    for (size_t i = 0; i < _m.regions.size(); ++i) {
        if (_desired[i] != kFull) continue;
        const glm::dvec2 lo(_m.regions[i].lo), hi(_m.regions[i].hi);
        if (reachDistance(pointRect(_eye, lo, hi)) > _o.chunkRadius) continue;
        band.push_back(int(i));
        _nearEyeChunks[i] = pointRect(_eye, lo, hi) <= _o.chunkRadius;
    }
    std::sort(band.begin(), band.end(), [&](int x, int y) {
        return _key[size_t(x)] != _key[size_t(y)] ? _key[size_t(x)] < _key[size_t(y)] : x < y;
    });
    for (int i : band) {
        const uint64_t bytes = cost(i, false, true);
        if (_o.budgetBytes > 0 && total + bytes > _budget) {
            _nearEyeChunks[size_t(i)] = 0;
            continue;
        }
        _desiredChunks[size_t(i)] = 1;
        total += bytes;
    }
}

// 0: a full level or chunk part wanted near the eye itself; 1: a coarse one; 2: wanted only for the lookahead.
int RegionPager::urgency(const Job& j) const {
    const bool nearEye = j.chunks ? _nearEyeChunks[size_t(j.region)] != 0 : _nearEye[size_t(j.region)] != 0;
    return nearEye ? (j.coarse ? 1 : 0) : 2;
}

void RegionPager::drop(int region, bool coarse, RegionPagerDelta* delta, bool chunks) {
    hold(Job{region, coarse, chunks})[size_t(region)] = 0;
    // Not handed to the caller yet: freed here.
    auto& arrived = delta->arrived;
    for (auto it = arrived.begin(); it != arrived.end(); ++it)
        if (it->region == region && it->coarse == coarse && it->chunks == chunks) {
            arrived.erase(it);
            ++_stats.discarded;
            return;
        }
    delta->dropped.push_back({region, coarse, chunks});
    ++_stats.unloads;
}

void RegionPager::schedule(RegionPagerDelta* delta) {
    const int n = int(_m.regions.size());
    // Drop what is not wanted; a region changing level keeps its old level
    // until the new one arrives (dropped below if the budget needs the room).
    for (int i = 0; i < n; ++i) {
        const uint8_t want = _desired[size_t(i)];
        const bool hasWanted = (want == kFull && _holdFull[size_t(i)]) || (want == kCoarse && _holdCoarse[size_t(i)]);
        if (_holdFull[size_t(i)] && want != kFull && (want == kNone || hasWanted)) drop(i, false, delta);
        if (_holdCoarse[size_t(i)] && want != kCoarse && (want == kNone || hasWanted)) drop(i, true, delta);
        if (_holdChunks[size_t(i)] && !_desiredChunks[size_t(i)]) drop(i, false, delta, true);
    }
    // Cancel queued loads that are no longer wanted.
    std::lock_guard<std::mutex> lock(_mutex);
    for (auto it = _queue.begin(); it != _queue.end();) {
        if (!wanted(*it)) {
            flight(*it)[size_t(it->region)] = 0;
            it = _queue.erase(it);
        } else {
            ++it;
        }
    }
    // The loads still to start, most urgent first.
    // Levels before chunk parts at the same urgency and distance.
    auto before = [&](const Job& a, const Job& b) {
        const int ua = urgency(a), ub = urgency(b);
        if (ua != ub) return ua < ub;
        if (_key[size_t(a.region)] != _key[size_t(b.region)]) return _key[size_t(a.region)] < _key[size_t(b.region)];
        if (a.region != b.region) return a.region < b.region;
        return a.chunks < b.chunks;
    };
    std::vector<Job> wants;
    for (int i = 0; i < n; ++i) {
        const uint8_t want = _desired[size_t(i)];
        if (want == kNone) continue;
        const Job level{i, want == kCoarse, false};
        if (!hold(level)[size_t(i)] && !flight(level)[size_t(i)]) wants.push_back(level);
        const Job part{i, false, true};
        if (_desiredChunks[size_t(i)] && !_holdChunks[size_t(i)] && !_flightChunks[size_t(i)]) wants.push_back(part);
    }
    std::sort(wants.begin(), wants.end(), before);
    // Queued loads in the same order: the queue is rebuilt, the new ones merged in.
    std::vector<Job> queued(_queue.begin(), _queue.end());
    _queue.clear();
    const RegionPagerStats now = stats();
    uint64_t resident = now.residentCost, residentFiles = now.residentBytes;
    for (const Job& w : wants) {
        const uint64_t need = cost(w.region, w.coarse, w.chunks);
        if (_o.budgetBytes > 0 && resident + need > _budget) {
            // The region's other level makes room, if it has one.
            const bool other = !w.coarse;
            if (!w.chunks && (other ? _holdCoarse : _holdFull)[size_t(w.region)]) {
                drop(w.region, other, delta);
                resident -= cost(w.region, other);
                residentFiles -= levelBytes(w.region, other);
            }
            if (resident + need > _budget) continue;  // waits for room (an old level leaving)
        }
        flight(w)[size_t(w.region)] = 1;
        resident += need;
        residentFiles += levelBytes(w.region, w.coarse);
        queued.push_back(w);
    }
    std::stable_sort(queued.begin(), queued.end(), before);
    _queue.assign(queued.begin(), queued.end());
    _stats.peakResidentCost = std::max(_stats.peakResidentCost, resident);
    _stats.peakResidentBytes = std::max(_stats.peakResidentBytes, residentFiles);
    _work.notify_all();
}

void RegionPager::update(const glm::dvec3& eye, const glm::dvec3& velocity) {
    VISTA_CHECK(finite(eye) && finite(velocity));
    _eye = glm::dvec2(eye);
    double lookahead = _o.prefetchS;
    if (!_o.wait) {
        std::lock_guard<std::mutex> lock(_mutex);
        for (double s : _fullLoadS) lookahead = std::max(lookahead, kLookaheadLoads * s);
        _stats.fullLoadSMax = _fullLoadSMax;
    }
    lookahead = std::min(lookahead, std::max(_o.prefetchS, kMaxPagedPrefetchS));
    _stats.lookaheadS = lookahead;
    _stats.peakLookaheadS = std::max(_stats.peakLookaheadS, lookahead);
    _ahead = _eye + glm::dvec2(velocity) * lookahead;
    _reach = glm::length(glm::dvec2(velocity)) * lookahead;
    _haveEye = true;
    computeDesired();
    computeShortfall();
    schedule(&_pending);
}

void RegionPager::computeShortfall() {
    _shortfall = RegionShortfall();
    const double reach = std::max(_o.radius, _o.far);
    int nearest = -1;
    double best = 0;
    for (size_t i = 0; i < _m.regions.size(); ++i) {
        const PagedRegionEntry& r = _m.regions[i];
        if (r.empty) continue;
        const double d = pointRect(_eye, glm::dvec2(r.lo), glm::dvec2(r.hi));
        if (d == 0) _shortfall.regions.push_back(int(i));
        if (d <= reach && (nearest < 0 || d < best)) nearest = int(i), best = d;
    }
    if (_shortfall.regions.empty() && nearest >= 0) _shortfall.regions.push_back(nearest);
    _shortfall.needCoarse = _shortfall.needFull = _reserve;
    for (int i : _shortfall.regions) {
        _shortfall.needCoarse += cost(i, true);
        _shortfall.needFull += cost(i, false) + (_o.chunkRadius >= 0 ? cost(i, false, true) : 0);
        // Left out by the budget: neither level wanted though neither file failed.
        if (_o.budgetBytes > 0 && _desired[size_t(i)] == kNone && !_failedCoarse[size_t(i)]) _shortfall.starved = true;
    }
}

int RegionPager::belowDetail() const {
    if (!_haveEye) return 0;
    const double farM = _o.far > _o.radius ? _o.far : -1.0;
    int n = 0;
    for (size_t i = 0; i < _m.regions.size(); ++i) {
        const PagedRegionEntry& r = _m.regions[i];
        if (r.empty) continue;
        const double d = pointRect(_eye, glm::dvec2(r.lo), glm::dvec2(r.hi));
        if (d <= _o.radius) n += _holdFull[i] ? 0 : 1;
        else if (d <= farM) n += (_holdFull[i] || _holdCoarse[i]) ? 0 : 1;
    }
    return n;
}

void RegionPager::takeArrivals(std::deque<Done>& done, RegionPagerDelta* delta) {
    bool failed = false;
    for (Done& d : done) {
        const int i = d.job.region;
        const bool coarse = d.job.coarse;
        flight(d.job)[size_t(i)] = 0;
        if (!d.model) {
            (coarse ? _failedCoarse : _failedFull)[size_t(i)] = 1;  // a chunk part reads the full file
            delta->damaged.push_back(d.model.status().message());
            ++_stats.failed;
            failed = true;
            continue;
        }
        ++_stats.loads;
        _stats.chunkLoads += d.job.chunks ? 1 : 0;
        _stats.bytesRead += levelBytes(i, coarse);
        if (!wanted(d.job)) {
            ++_stats.discarded;  // no longer wanted: freed with `done`
            continue;
        }
        hold(d.job)[size_t(i)] = 1;
        RegionArrival a;
        a.region = i;
        a.coarse = coarse;
        a.chunks = d.job.chunks;
        a.model = std::move(*d.model);
        a.bytes = levelBytes(i, coarse);
        a.loader = d.loader;
        a.sequence = d.sequence;
        a.prepared = std::move(d.prepared);
        delta->arrived.push_back(std::move(a));
    }
    done.clear();
    // A failed full file: its coarse level is wanted instead.
    if (failed && _haveEye) computeDesired();
    // Old levels of regions whose new level arrived go now.
    schedule(delta);
}

RegionPagerDelta RegionPager::collect(bool wait) {
    RegionPagerDelta delta = std::move(_pending);
    _pending = RegionPagerDelta();
    std::deque<Done> done;
    {
        std::lock_guard<std::mutex> lock(_mutex);
        done.swap(_done);
    }
    takeArrivals(done, &delta);
    if (_o.wait || wait) {
        Stopwatch sw;
        for (;;) {
            bool inFlight = false;
            for (size_t i = 0; i < _flightFull.size() && !inFlight; ++i)
                inFlight = _flightFull[i] || _flightCoarse[i] || _flightChunks[i];
            if (!inFlight) break;
            delta.waited = true;
            {
                std::unique_lock<std::mutex> lock(_mutex);
                _arrived.wait(lock, [this] { return _queue.empty() && _busy == 0; });
                done.swap(_done);
            }
            takeArrivals(done, &delta);
        }
        if (delta.waited) {
            ++_stats.framesWaited;
            _stats.waitMs += sw.ms();
        }
    }
    std::sort(delta.dropped.begin(), delta.dropped.end(), [](const RegionDrop& a, const RegionDrop& b) {
        if (a.region != b.region) return a.region < b.region;
        return a.coarse != b.coarse ? a.coarse < b.coarse : a.chunks < b.chunks;
    });
    std::stable_sort(delta.arrived.begin(), delta.arrived.end(), [](const RegionArrival& a, const RegionArrival& b) {
        if (a.coarse != b.coarse) return !a.coarse;
        return a.region != b.region ? a.region < b.region : a.chunks < b.chunks;
    });
    return delta;
}

void RegionPager::setBudget(uint64_t bytes) {
    _o.budgetBytes = bytes;
    _budget = bytes > _reserve ? bytes - _reserve : std::min<uint64_t>(bytes, 1);
}

bool RegionPager::idle() const {
    for (size_t i = 0; i < _flightFull.size(); ++i)
        if (_flightFull[i] || _flightCoarse[i] || _flightChunks[i]) return false;
    return true;
}

RegionPagerStats RegionPager::stats() const {
    RegionPagerStats s = _stats;
    s.loadingReserve = _reserve;
    s.residentBytes = s.residentCost = s.heldCost = 0;
    s.residentFull = s.residentCoarse = 0;
    for (size_t i = 0; i < _holdFull.size(); ++i) {
        if (_m.regions[i].empty) continue;
        const int r = int(i);
        if (_holdFull[i] || _flightFull[i]) s.residentBytes += levelBytes(r, false), s.residentCost += cost(r, false);
        if (_holdCoarse[i] || _flightCoarse[i]) s.residentBytes += levelBytes(r, true), s.residentCost += cost(r, true);
        if (_holdChunks[i] || _flightChunks[i])
            s.residentBytes += levelBytes(r, false), s.residentCost += cost(r, false, true);
        s.heldCost += (_holdFull[i] ? cost(r, false) : 0) + (_holdCoarse[i] ? cost(r, true) : 0) +
                      (_holdChunks[i] ? cost(r, false, true) : 0);
        s.residentChunks += _holdChunks[i] ? 1 : 0;
        s.residentFull += _holdFull[i] ? 1 : 0;
        s.residentCoarse += _holdCoarse[i] ? 1 : 0;
    }
    return s;
}

std::vector<uint8_t> RegionPager::held() const {
    std::vector<uint8_t> out(_holdFull.size(), kNone);
    for (size_t i = 0; i < out.size(); ++i) out[i] = _holdFull[i] ? kFull : (_holdCoarse[i] ? kCoarse : kNone);
    return out;
}

}  // namespace vista
