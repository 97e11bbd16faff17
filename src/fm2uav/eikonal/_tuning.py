"""The parallel march's tunable numbers: when it runs, how it cuts the grid, how wide its
windows are (issue 27).

Read by :mod:`fm2uav.eikonal._parallel` at call time, never by a compiled kernel, so a
number here can be changed (or patched by a test or a sweep, ``monkeypatch.setattr(_tuning,
"WINDOW_NODES", ...)``) without recompiling the kernels: an edit of ``_parallel.py`` itself,
even of a constant, invalidates numba's cache of all its kernels (~10 minutes to rebuild).
The numbers the kernels read (``FAR_ONE_AXIS``, the heap and pool
reserves) stay there. Each number says what was measured to choose it
(docs/performance.md, "Both cores").
"""

from __future__ import annotations

#: The windows meet at a barrier several hundred times per march: a thread that waits there spins
#: only briefly and then sleeps (OpenMP's default spins ~300,000 times), or on a busy machine the
#: spinning thread takes the core its partner needs (measured on 2048^2 with 10 runnable processes
#: on 2 cores: 3.4 CPU-s spinning, 0.56 s passive, serial 0.53 s). The brief spin
#: (:data:`SPIN_COUNT`, ~0.1 ms by libgomp's estimate) spares most wake-ups from sleep: near idle
#: (``benchmarks/wait_policy.py``, medians of 9), two threads' wall on 2048^2 FM²-shaped order 1
#: 145.1 / 133.3 / 132.4 ms at 2000 / 5000 / 10000 spins, at a constant speed 139.1 / 127.3 / 125.0
#: ms, the CPU 253 -> 249 and 261 -> 244 ms (a sleep and its wake-up cost more than the spin);
#: 160^3 FM²-shaped 278.6 / 279.0 / 267.3 ms. Under load (two busy loops beside, load ~3) 10000
#: spins cost the CPU +10 % and the wall 0-8 % (docs/performance.md, "Spinning briefly"). Read by
#: libgomp when numba first starts its thread pool; values set by the user stay (a user's
#: ``OMP_WAIT_POLICY`` keeps libgomp's own spin count for it).
SPIN_COUNT = 10000
#: Environment variable with the default thread count of the march (an integer >= 1).
THREADS_ENV = "FM2UAV_THREADS"
#: Whether :func:`fm2uav.eikonal.fast_marching` marches order 2 on slabs too (False: order 2
#: marches serially). The order-2 slabs give the serial march's times bit for bit on every case
#: measured (tests/eikonal/test_fmm_parallel.py; the 2048² FM²-shaped map and the 1000 x 1000 x 40
#: terrain march, 25.8 M nodes): a node's time is the one the serial march keeps, the lowest of its
#: updates at its neighbours' freezes in time order (:func:`_parallel._serial_time2`). Only a tie
#: (two nodes of one stencil frozen at the very same time) could make them differ, where the serial
#: march's pick depends on its queue.
ORDER2 = True
#: Grids of fewer nodes march serially whatever the thread count. Measured
#: (benchmarks/bench_core.py, "threads" rows, a machine at load 9 on 2 cores): on 1024^2 the
#: busiest thread takes 0.06 s of the serial 0.099 CPU-s (1.65x on an idle machine) and the wall
#: time is equal; below, a window holds fewer nodes per barrier and the wall time on a busy machine
#: decides: kept serial.
PARALLEL_MIN_NODES = 1_000_000
#: 3D order 2 marches on slabs only from this many nodes: its repairs near the ghosts (a node's
#: time from scratch, :func:`_parallel._serial_time2`) cost more on thin slabs. Measured (3
#: December 2026, machine at load 4.5-4.8, medians of 2): 160^3 FM²-shaped (20-row slabs) CPU 0.97
#: -> 2.31 s, busiest thread 0.98 -> 1.34 s (0.73x: slower); the 1000 x 1000 x 40 terrain march
#: (125-row slabs) busiest thread 10.4 -> 5.0 s. Since (5 December 2026: the window's flags on one
#: line and its queue in registers, 2 slabs per thread, windows of 16384 nodes; idle machine, wall,
#: 2 threads over 1, medians of 5): 160^3 (4.1 M) FM²-shaped 1.06-1.28x, constant 1.14-1.17x,
#: smooth 1.11-1.21x; 128^3 (2.1 M) 0.87-0.88x, 100^3 0.38-0.69x: from 4 M nodes.
ORDER2_MIN_NODES_3D = 4_000_000
#: 2D order 2 marches on slabs only from this many nodes (below: one thread, never slower). Its
#: slab window costs more a node than the serial order-2 march (its neighbours' freeze order
#: checked, :func:`_parallel._serial_time2`'s from-scratch repairs near the ghosts), which a bigger
#: grid's memory traffic hides. Measured (3 December 2026, load 6-7, medians of 3, CPU times):
#: 2048^2 (4.2 M) FM²-shaped one slab on one thread 1.25x the serial march's CPU (smooth 1.32x)
#: before any repair, two threads' CPU 0.388 -> 0.621 s (1.60x; smooth 0.524 -> 0.751 s), busiest
#: thread 1.20x (smooth 1.32x; `make bench` on the idle machine: wall 0.97x / 1.16x); 2900^2 (8.4
#: M) FM²-shaped CPU 0.875 -> 1.199 s (1.37x), busiest thread 1.43x (smooth 1.69x; load 8.7-9);
#: 4096^2 (16.8 M) FM²-shaped CPU 1.926 -> 2.338 s (1.21x), busiest thread 1.60x (smooth 1.69x). On
#: the idle machine the 2048^2 wall ratio was ~0.8x the busiest thread's: from 2^23 (8.4 M) nodes
#: on the slabs. Since (5 December 2026, as the 3D floor's; windows of 8192 nodes, the slabs taken
#: in turn): 2048^2 (4.2 M) FM²-shaped 1.16-1.22x, constant 1.06-1.18x, smooth 1.14x; 1448^2 (2.1
#: M) 0.89-1.04x, 1024^2 0.83-0.85x: from 2^22 nodes (2048^2).
ORDER2_MIN_NODES_2D = 2**22
#: Each slab gets at least this many x-slabs (rows), else fewer slabs are used.
MIN_SLAB_ROWS = 16
#: ... and at least this many nodes (but every thread one slab): thin slabs cost repairs. Measured
#: on 1024^2 smooth (2 threads, CPU over the serial march's, loaded machine): 2/4/8 slabs per
#: thread 1.05x/1.08x/1.24x at the same windows' balance (1.94-1.96).
MIN_SLAB_NODES = 2**17
#: Slabs per thread, thread ``t`` marching slabs ``t, t + threads, ...``: strips interleaved across
#: the grid keep both threads busy when the wave starts off-centre (and
#: :func:`_parallel.slab_bounds` places the cuts). Measured on the FM²-shaped fields (source at 0.3
#: of x), 2 threads, windows of 32768 nodes, balanced cuts: the windows' balance
#: (``stats["balance"]``, the speed-up they allow) 2D 4/8 slabs per thread 1.69/1.76, 3D 2/4
#: 1.65/1.84, process CPU the same within noise (0.88-0.96x the serial march's; the exchange reads
#: only the nodes frozen in the boundary rows). In 2D the better balance of 8 did not show in wall
#: time on the idle machine (2048², 2 threads, medians of 5 interleaved: constant 0.257/0.261 s,
#: smooth 0.292/0.302 s, FM²-shaped 0.234/0.248 s with 4/8 slabs per thread): 2D keeps 4. (With
#: :data:`SHARE_SLABS`, 2D FM²-shaped 4/8: balance 1.76/1.81 for 2.2x the re-opened nodes.) Keyed
#: by (dimension, order): order 2's ghosts, two rows deep, re-open more nodes on thinner slabs, and
#: its repairs (a node's time from scratch, :func:`_parallel._serial_time2`) cost more; in 3D it
#: takes 2 (5 December 2026, idle machine, 2 threads over 1, medians of 3, windows of 16384 nodes:
#: 160^3 FM²-shaped 0.61x / 1.28x with 3 / 2 slabs per thread, 467,000 / 43,000 nodes re-opened;
#: the terrain march 3.91 / 3.72 s; docs/performance.md).
SLABS_PER_THREAD = {(2, 1): 4, (3, 1): 4, (2, 2): 4, (3, 2): 2}
#: Target number of nodes frozen per window (all slabs together); the window width adapts to it.
#: Fewer, wider windows cost fewer barriers and more repairs: measured on 160^3 (2 threads, CPU
#: over the serial march's, loaded machine) constant speed 8192/16384/32768 nodes
#: 1.15x/0.97x/0.85x; FM²-shaped 32768/65536 0.92x/2.4x (wider windows than the wave's crossing of
#: a slab re-open nodes in cascades). Keyed by (dimension, order): order 2 re-opens more a window
#: (5 December 2026, idle machine, 2 threads over 1, medians of 5, the slabs taken in turn: 2048^2
#: FM²-shaped 1.13x / 1.16x with 16384 / 8192 nodes, 95,000 / 52,000 re-opened, 4096 0.90x; 160^3
#: FM²-shaped, 2 slabs per thread, 32768 / 16384 / 8192 / 4096 1.03x / 1.28x / 1.25x / 1.10x; the
#: terrain march 16384 / 32768 nodes 3.72 / 3.57-3.75 s; docs/performance.md).
#: On OpenMP (session 26, 5 December 2026; before, numba had run the regions on TBB, whose
#: second thread joined each region ~130 us late, docs/performance.md "Where two threads
#: lose") narrower windows won, their barriers now cheap (two threads over one, wall, medians
#: of 5-9 interleaved in one process): 2D order 1 32768 / 16384 nodes 2048^2 FM²-shaped
#: 1.50-1.53x / 1.55-1.60x, smooth 1.49-1.57x / 1.48-1.64x, constant 1.33-1.69x /
#: 1.32-1.71x, 1448^2 FM²-shaped 1.41x / 1.50x, 1024^2 FM²-shaped 1.20x / 1.26x, smooth
#: 1.36x / 1.42x (8192 as 16384 on 2048^2); 3D order 1 32768 / 16384 / 8192 160^3
#: FM²-shaped 1.69x / 1.78x / 1.83x, constant 1.90x / 2.11x / 2.08x, smooth (16384 / 8192)
#: 1.70x / 1.86x (4096: 1.59x, 1.75x); 3D order 2, 2 slabs per thread, 16384 / 8192 160^3
#: FM²-shaped 1.32x / 1.44x, constant 1.09x / 1.37x, smooth 1.18x / 1.27x (4 slabs of
#: 4096: 1.33x / 1.28x / 0.94x; 3 of 8192: 1.10x / 1.07x), the terrain march 3.86 / 3.29-3.68
#: s (4 of 4096 3.08-3.22 s, 3 of 8192 3.14 s, 4 of 8192 3.39-3.42 s).
#: 3D order 1 again (session 34, 6 December 2026, after the slab march's kept pools: 160^3, two
#: threads, alternating processes, medians of 6 rounds of 5; 16384 / 32768 against 8192):
#: constant 0.915x / 0.871x, FM²-shaped 0.990x / 1.033x, smooth 0.911x / 0.864x: 16384.
WINDOW_NODES = {(2, 1): 16384, (3, 1): 16384, (2, 2): 8192, (3, 2): 8192}
#: Per order, the window nodes of a 2D march on slabs whose speeds vary (the interleaved
#: layout) on its usual slabs (not one a thread, :data:`FEWER_SLABS_2D`). Measured (6
#: December 2026, session 37, 2048^2 order 2, two threads, one process alternating the
#: settings, medians of 7 / 9; 4096 / 8192 nodes): FM²-shaped seeds 0 / 1 / 3 153.5 / 160.1,
#: 147.7 / 151.0, 145.4 / 150.8 ms, smooth from (614, 681) 187.6 / 195.3; but constant speed
#: (separate arrays) from (819, 1024) 165.8 / 160.7 and the smooth field from the centre on
#: one slab a thread 167.7 / 164.3: those keep :data:`WINDOW_NODES`.
WINDOW_NODES_2D_VARYING = {2: 4096}
#: Share the slabs among the threads anew before every window, longest first by the freezes of the
#: last window, when that predicts a shorter window than the fixed interleave
#: (:func:`_parallel._assign`); False: always the interleave. Windows' balance with / without (2
#: threads, 4 slabs per thread): FM²-shaped 2048^2 1.654 -> 1.759, 160^3 1.84 -> 1.90; constant
#: speed the same (1.99, 1.93 -> 1.95).
SHARE_SLABS = True
#: 2D: the threads take the slabs of a window (and of its exchange) in turn, the next not taken
#: when done with the last, by decreasing predicted work (:func:`_parallel._take`) instead of lists
#: fixed before the window (:func:`_parallel._assign`): the lists predict a window's work by the
#: last one's, which lags the wave where it enters or leaves slabs; taken in turn, a window's slabs
#: go to the threads by their actual work (and a thread the machine holds back takes fewer).
#: Simulated from the serial times of the bench's FM²-shaped 2048^2 maps (seeds 0-3, windows of
#: 32768 nodes, equal slabs), the windows' balance with 8 / 16 slabs: lists 1.78-1.81 / 1.82-1.88,
#: in turn 1.79-1.86 / 1.91-1.96 (constant speed 2.00 / 2.00 either way). Needs
#: :data:`SHARE_SLABS`. Measured (3 December 2026, load 6, the march's own counts: the balance an
#: idle machine gets, :func:`_parallel._in_turn`) on those maps marched, 4 slabs per thread:
#: balance 1.816/1.855/1.880/1.819 with the lists, 1.847/1.899/1.901/1.852 in turn, the same nodes
#: re-opened (the windows do not depend on who runs a slab) and the same CPU; 8 slabs per thread
#: 1.895-1.947 for 1.7-2x the re-opened nodes (two threads' CPU +3 %: no gain). Wall near idle
#: (load 1.0-1.1, 2048^2, medians of 5-7 interleaved, two threads over one): lists / in turn
#: constant 1.83-1.84x / 1.87-1.94x, smooth 1.80x / 1.87x, FM²-shaped 1.51x / 1.57-1.59x. On: 2D
#: order 1, 4 slabs per thread. Order 2 too (5 December 2026, 2048^2, 4 slabs per thread, windows
#: of 8192 nodes, 2 threads over 1, medians of 5: lists / in turn FM²-shaped 1.08x / 1.16x, smooth
#: 1.03x / 1.14x, constant 1.02x / 1.17x).
DYNAMIC_2D = True
#: With :data:`DYNAMIC_2D`: each thread takes first the slabs it ran in the last window, by
#: decreasing predicted work, then those the others have not taken (:func:`_parallel._affine`):
#: a slab run on another core than before reads its rows and queue from that core's cache.
#: Measured: see :func:`_parallel._affine` and docs/performance.md (session 40).
SLABS_STAY_2D = True
#: 3D: the slabs of each window taken so too, in turn each thread first on its own
#: (:data:`SLABS_STAY_2D`), instead of the lists of :data:`SHARE_SLABS` (longest first by the
#: last window, each list fixed for the window). On 160^3 two threads' windows took 418 CPU-ms
#: with those lists against 405 with the slabs fixed (order 1; order 2 520 / 506). Measured (7
#: December 2026, session 40, two threads, one process alternating the settings, medians of
#: 5 / 7 in two runs, on / off): 160^3 FM²-shaped order 1 0.954x / 0.971x (seed 1 0.959x),
#: order 2 0.988x / 0.983x (seed 2 0.989x), smooth order 1 0.946x, order 2 1.000x, constant
#: order 1 1.011x (one slab a thread: the same slabs); the 1000 x 1000 x 40 terrain march
#: (medians of 3) 2.84 / 3.16 s, the times the same bit for bit.
SLABS_STAY_3D = True
#: The split of two slabs is chosen on a march over every ``COARSE``-th node per axis (2D; 3D:
#: ``COARSE_3D``), ~0.5 % (2D) and ~0.2-1.5 % (3D) of the work of the full march (serial time: the
#: second thread waits). 2D: the windows' balance on FM²-shaped 2048^2 maps (seeds 0-3, with
#: :func:`_parallel._assign`) averaged 1.827 / 1.823 / 1.813 / 1.768 with every 8th / 16th / 32nd
#: node / equal slabs, the coarse march 8 / 2 / 0.5 ms.
COARSE = 16
#: 3D keyed by order. Order 1 takes every 8th node: the placing runs on the calling thread while
#: the other waits, 6.8-10.5 ms on the bench's 160^3 fields with every 4th node against 2.3-2.8
#: ms with every 8th, for the same cuts or as good (6 December 2026, session 39, two threads,
#: one process alternating the settings, medians of 9-11: constant 0.973x / 0.970x, smooth
#: 0.983x, FM²-shaped seeds 0 / 1 / 2 / 3 0.970x / 0.916x / 0.966x / 0.972x). Order 2 keeps
#: every 4th: there the coarse march also chooses the slab count (:data:`MORE_SLABS_3D`), and
#: every 5th / 6th / 8th node cost the FM²-shaped field 1.007x / 1.206x / 1.016x (session 38).
COARSE_3D = {1: 8, 2: 4}
#: The coarse march's step along z in 3D (a terrain's layers are few: 40).
COARSE_3D_Z = 4
#: Whether the cuts are placed for the slabs shared anew before each window (the least share of a
#: time bin any sharing allows, :func:`_parallel.slab_bounds`) rather than for the fixed
#: interleave. Simulated on the bench's FM²-shaped 2048^2 map from the serial times (windows of
#: 32768 nodes in time order, the slabs shared as :func:`_parallel._assign`), 8 slabs: windows'
#: balance 1.78 -> 1.84 (16 slabs 1.83 -> 1.84). 3D from :data:`SHARED_CUTS_MIN_NODES_3D` nodes
#: only (below, the interleave's cuts).
SHARED_CUTS = {2: True, 3: True}
#: 3D grids of fewer nodes keep the interleave's cuts: on the bench's 160^3 fields (order 1)
#: constant and smooth speed get the same cuts either way, the FM²-shaped one other cuts that
#: simulate worse (1.921 -> 1.910); the 1000 x 1000 x 40 terrain plan's order-2 march (40 M nodes)
#: gets the shared cuts, measured 1.881 -> 1.922 (docs/performance.md): from 2^24 nodes, the
#: bench's 160^3 grids (both orders) below.
SHARED_CUTS_MIN_NODES_3D = 2**24
#: Bins of the split estimate, each as many coarse nodes in time order (stand-ins for the windows).
SPLIT_BINS = 256
#: Bytes faulted in per call of :func:`_parallel._touch` by :class:`_parallel._PageToucher` (its
#: stop check): one huge page, so the block's end waits for at most one fault. With 16 MiB the cuts
#: of 2048^2 at a constant speed (3.6 ms) waited 13.8 ms for the toucher to end its chunk, with 2
#: MiB 0.09 ms (medians of 9; FM²-shaped and smooth 0.1-0.5 ms either way).
TOUCH_CHUNK = 2 * 2**20
#: 2D: the exchange before each window runs on the calling thread alone (the parallel
#: region's iterations in turn), not on every thread, keyed by order: an order-1 exchange is a
#: row per slab side (the busiest thread's share summed over the 108 exchanges of the bench's
#: FM²-shaped 2048^2 map: ~1 ms), while waking the other thread for it cost ~0.1 ms of wall a
#: region (3 December 2026; docs/performance.md). Order 2's exchanges are ten times order 1's
#: (2048^2 FM²-shaped: 10.7 ms on one thread) and, on OpenMP, a region costs ~1 us: on every
#: thread they gained 2-4 % (5 December 2026, 2048^2, two threads over one, alone / on every
#: thread, medians of 7 and 9 in two runs: FM²-shaped 1.28x / 1.32x and 1.27x / 1.29x, smooth
#: 1.22x / 1.24x and 1.21x / 1.25x, constant 1.30x / 1.27x and 1.27x / 1.32x). Order 1: the
#: same either way (1.61x / 1.62x, 1.65x / 1.66x). Passed to the drive (not compiled in).
EXCHANGE_ALONE_2D = {1: True, 2: False}
#: Keyed by dimension and order: after the first, each exchange runs in the windows' parallel
#: region, a slab's as soon as the windows of it and its two neighbours are done, on whichever
#: thread is free (the drive's ``merge``; not where :data:`EXCHANGE_ALONE_2D` holds): the
#: thread done with its slabs first exchanges while the other finishes, and a region a window
#: is saved. The times are the same bit for bit. Passed to the drive (not compiled in).
EXCHANGE_IN_WINDOW = {(2, 1): True, (3, 1): True, (2, 2): True, (3, 2): True}
#: 3D grids of at least this many nodes (the terrain plan's march: 1000 x 1000 x 40, 42 M with
#: its padding) take :data:`BIG_3D_SLABS_PER_THREAD` and :data:`BIG_3D_WINDOW_NODES` (keyed by
#: order) instead of :data:`SLABS_PER_THREAD` and :data:`WINDOW_NODES`: slabs of ~125 rows are
#: thick enough that four per thread re-open few nodes, and balance the windows better than two.
#: Measured on that march (5 December 2026, session 27, idle machine, 2 threads, the settings
#: interleaved in one process, medians of 3 / 5 in two runs, the second in a slower minute):
#: 2 slabs per thread with windows of 8192 nodes 3.567 / 4.548 s (windows' balance 1.694,
#: 10,946 nodes re-opened), 4 with 4096 3.137 / 3.645 s (balance 1.917, 15,456 re-opened), 4 with
#: 8192 3.594 s in the slower run (42,119 re-opened), 5 with 4096 3.692 s (1.908); the times the
#: same bit for bit. The bench's 160^3 grids (4.1 M, slabs of 40 rows) stay below: with 4 slabs
#: per thread of 4096 nodes (session 26) FM²-shaped 1.33x, smooth 0.94x on two threads.
BIG_3D_NODES = 2**24
BIG_3D_SLABS_PER_THREAD = {1: 4, 2: 4}
BIG_3D_WINDOW_NODES = {1: 8192, 2: 4096}
#: The cuts between slabs keep this many rows from a point source's row (keyed by dimension and
#: order; :func:`_parallel.clear_of_sources`): a cut through the source runs along the wave, and the nodes
#: beside its ghosts are re-opened all the way out. Measured (5 December 2026, session 27, 2
#: threads, the cut through the centre moved, medians of 5 interleaved in one process): 160^3
#: smooth speed (source at the centre) order 1, 0 / 4 / 8 rows above / 8 below: 352.2 / 376.6 /
#: 319.5 / 297.4 ms (1.56x / 1.46x / 1.72x / 1.85x over one thread), 54,663 / 30,029 / 12,631 /
#: 8,894 nodes re-opened, windows' balance 1.966 / 1.953 / 1.928 / 1.928; order 2, 0 / 4 / 8 rows
#: above: 1.25x / 1.49x / 1.61x, 58,329 / 36,760 / 14,882 re-opened. 2048^2 smooth: 8 rows changed
#: nothing (order 2: 66,232 / 67,295 re-opened; the other six cuts re-open as many), 32 rows
#: 43,184, the wall within the spread: 2D keeps its cuts. 2D order 2 on one slab a thread
#: (:data:`FEWER_SLABS_2D`, session 37, 6 December 2026): its one cut, placed 16 rows from the
#: bench's smooth source (1040 of 2048) inside the source ball (radius 102 rows), took every
#: re-opened node (45,808, all in the slab beyond it: the rays cross the cut at a shallow angle
#: all the way out) and 22 % more CPU than the other slab. 2048^2 two threads, one process
#: alternating the settings, medians of 7, 0 / 32 / 64 / 96 rows: order 2 smooth 167.6 / 166.1 /
#: 148.5 / 148.9 ms (one thread 232.3; 45,808 / 31,308 / 17,940 / 12,265 re-opened), constant
#: (8 slabs) 158.8 / 151.1 / 146.3 / 146.8, constant from (819, 1024) 168.0 / 155.1 / 148.9 /
#: 152.1, FM²-shaped 145.3 / 145.2 / 146.2 / 146.0, smooth from (614, 681) 187.1 / 184.1 /
#: 184.6 / 183.9; order 1 loses (0 / 64 / 96: smooth 114.6 / 117.8 / 119.0, constant 92.0 /
#: 94.7 / 95.5, FM²-shaped 98.9 / 99.1 / 100.0). 3D order 2 keeps 8 (160^3, 8 / 16 / 32: smooth
#: 355.5 / 368.1 / 407.7, constant 256.6 / 283.8 / 330.4, FM²-shaped 340.6 / 339.9 / 374.2).
#: 3D order 1 (one slab a thread on constant speed since session 36: its one cut re-opens on
#: one side only) takes 4: 160^3, two threads, medians of 5 / 5 / 7 in three runs, 4 rows over
#: 8: constant 0.963 / 0.972 / 0.950x, from (80, 60, 80) 0.969 / 0.968 / 0.967x, from (75, 80,
#: 80) 1.015 / 0.985 / 0.989x, smooth 0.968 / 0.992 / 0.981x, FM²-shaped 0.996 / 1.002 / 0.984x
#: (6 rows: 0.972 / 0.956, 0.984 / 0.976, 0.974 / 1.018, 0.993 / 0.983, 0.990 / 0.980; 2 rows
#: from (75, 80, 80) 1.046x).
SOURCE_CUT_ROWS = {(2, 1): 0, (2, 2): 64, (3, 1): 4, (3, 2): 8}
#: Whether the parallel march's lean-layout times (the terrain plan's march: 42 M nodes, 336
#: MB; :func:`fm2uav.eikonal._kernels._buffers`) are mapped on huge pages, as every other work
#: buffer. False: small pages. On this virtual machine a fresh huge page's first touch took
#: ~4.5 ms (the padding's system CPU 0.93-1.0 s for ~210 of them): the free memory it hands
#: back to the host is whole huge pages, while recently freed small pages are still backed.
#: Measured (5 December 2026, session 28, ``benchmarks/terrain_stages`` conditions, 2 threads,
#: the two settings in alternating fresh processes, medians of 3 / 5 in two runs; huge / small):
#: padding 0.600 / 0.334 s and 0.632 / 0.248 s, march kernel 2.920 / 2.989 s and 2.874 / 2.955
#: s (the TLB misses), plan 4.437 / 4.202 s and 4.364 / 4.032 s. V too on small pages: plan
#: 4.408 / 4.277 s (the kernel +0.136 s). The serial march keeps huge pages: on one thread its
#: kernel lost more (5.712 / 6.193 s) than the padding gained (1.016 / 0.694 s).
LEAN_TIMES_HUGE = False
#: 3D grids below :data:`BIG_3D_NODES`, keyed by order: (slabs per thread, window nodes) taken
#: instead of :data:`SLABS_PER_THREAD` and :data:`WINDOW_NODES` where the coarse march of
#: :func:`_parallel.slab_bounds` predicts for them a windows' critical path shorter by the
#: factor :data:`MORE_SLABS_GAIN` (the slabs shared as :func:`_parallel._assign` shares them).
#: A source off-centre leaves 2 slabs per thread unbalanced; thinner slabs re-open more nodes,
#: which pays only there. Measured (5 December 2026, session 28, 160^3, 2 threads, the settings
#: interleaved in one process, medians of 5; two threads over one, 2 : 8192 / 3 : 4096):
#: FM²-shaped seeds 0 / 1 / 2 1.50x / 1.61x, 1.48x / 1.57x, 1.47x / 1.56x (windows' balance
#: 1.705 / 1.885, 1.699 / 1.854, 1.605 / 1.881), the coarse march's prediction 1.681 / 1.819,
#: 1.678 / 1.801, 1.593 / 1.818 (+7 to +14 %); smooth speed (centred source) 1.76x / 1.70x,
#: constant 1.68x / 1.55x, predicted +0.2 % and -0.4 %. Order 1 (1.84-1.98x) keeps its slabs.
MORE_SLABS_3D = {2: (3, 4096)}
MORE_SLABS_GAIN = 1.05
#: Whether a 3D march on slabs (grids below :data:`BIG_3D_NODES`, outside the lean layout)
#: whose nodes all have one speed takes one slab per thread where the coarse march of
#: :func:`_parallel.slab_bounds` reaches every coarse node (no walls) and predicts for them a
#: windows' critical path of at most :data:`FEWER_SLABS_COST` times that of its slabs. On a
#: uniform speed without walls the wave reaches the nodes symmetric about the source at one
#: time (a level-0 bucket of up to 48 nodes, megabytes apart); thick slabs keep them apart,
#: where fetching the next pop ahead pays (:func:`fm2uav.eikonal._kernels._pop_ahead`), and
#: fewer cuts re-open fewer nodes. Measured (6 December 2026, session 36, 160^3 constant speed,
#: two threads, medians of 5, one slab a thread / the slabs as before), source (80, 80, 80):
#: order 1 175.8 / 210.5 ms, order 2 252.7 / 301.7 ms; (75, 80, 80) 178.7 / 210.9, 267.3 /
#: 310.5; (80, 60, 80) 176.9 / 204.4, 251.4 / 303.2; (70, 80, 80) order 1 189.7 / 206.8 (the
#: predicted path 1.008x that of 8 slabs), order 2 kept its 4 slabs (1.018x). With the bench's
#: FM² walls as speed 0 (one speed elsewhere) from the centre one slab a thread took 213.6
#: against 206.4 ms (predicted 1.000x): walls break the symmetry, hence the coarse march must
#: reach every coarse node. Where the speeds vary thick slabs cost the windows more CPU (the
#: smooth field, order 1: 0.419 / 0.362 s), hence one speed only.
FEWER_SLABS_3D = True
FEWER_SLABS_COST = 1.01
#: Per order, whether a 2D march on slabs (outside the lean layout) takes one slab per thread
#: on the terms of :data:`FEWER_SLABS_3D` (no walls, a critical path of at most
#: :data:`FEWER_SLABS_COST` times that of its slabs), any speed. Measured (6 December 2026,
#: session 37, 2048^2, two threads, one process alternating the settings, medians of 7; wall,
#: one slab / four a thread, the cuts 64 rows off the source, :data:`SOURCE_CUT_ROWS`): order 2
#: from the centre (the prediction 0.991x / 0.996x) smooth 151.4 / 167.0 ms (one thread
#: 237.1), constant 135.9 / 145.8 (194.3); off-centre it loses where the prediction says so:
#: constant from (819, 1024) 164.4 / 150.5 (predicted 1.107x), smooth from (614, 681) 216.6 /
#: 185.2 (1.237x), the FM²-shaped map 175.8 / 147.9 (walls: never taken); constant from
#: (921, 1024) 148.8 / 150.4 (1.047x: kept). Before the cuts moved off the source (rows 0) the
#: smooth field gained as much (167.1 / 187.8 ms: 45,808 / 66,382 re-opened, windows' CPU 243 /
#: 280 ms over both threads against the serial kernel's 202) but constant speed did not
#: (166.4 / 159.5). Order 1 (its cuts as placed, rows 0) gains 1-3 %: smooth 113.1 / 116.0
#: ms, constant 89.4 / 89.9; a second run 115.1 / 116.7 and 89.7 / 92.5 (one thread 187.1,
#: 156.3), the FM²-shaped map (walls) 99.6 / 100.5 (noise: the same slabs).
FEWER_SLABS_2D = {1: True, 2: True}

#: 2D, keyed by order: the windows pipelined, no barrier between them: each window posts its
#: boundary nodes' times for its neighbours' next exchange, so a slab's next window waits for
#: its two neighbours' last windows only (:func:`_parallel._pipe_kernel`); not toward stop
#: nodes. False: a parallel region a window (:func:`_parallel._drive_kernel`); 3D always so
#: (its windows pass 1.6x with their regions). The times are the same (order 2 bit for bit).
#: Measured (7 December 2026, session 45, 2048^2, two threads, one process alternating the
#: settings, medians of 11, pipelined / regions): order 2 FM²-shaped 266.6 / 295.5 ms (1.68x /
#: 1.52x the serial march), its seed 1 240.2 / 247.5, smooth 349.0 / 355.0; order 1 FM²-shaped
#: 192.3 / 200.5 and 192.7 / 197.0, its seed 1 182.7 / 197.7, smooth 250.4 / 255.8, constant
#: 227.1 / 225.1 (docs/performance.md, session 45).
PIPELINE = {1: True, 2: True}
