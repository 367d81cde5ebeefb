"""What Rerun's file writer holds for the footer it writes at the end of a recording
(`RecordingStream.save(path, write_footer=True)`), per chunk, and what that depends on.

The writer keeps the footer's manifest (an entry per chunk) in memory until the file ends. This
logs ``--chunks`` small chunks of one scalar column on two timelines, round-robin over 24 entities
(as `sins-fw replay` logs its series), after ``--extra`` other columns were logged once each, and
prints the resident memory that grew per chunk and how far the peak rose at the end:

    python benchmarks/rerun_footer_memory.py --extra 0 --chunks 10000
    python benchmarks/rerun_footer_memory.py --extra 30 --chunks 10000 --kind temporal-components
    python benchmarks/rerun_footer_memory.py --extra 30 --chunks 10000 --kind static-components
    python benchmarks/rerun_footer_memory.py --extra 30 --chunks 10000 --kind entities
    python benchmarks/rerun_footer_memory.py --extra 30 --chunks 10000 --kind timelines

Results and their reading: benchmarks/peak_rss.md, "The footer's manifest".
"""

from __future__ import annotations

import argparse
import resource
import tempfile
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr


def rss_mb() -> float:
    return int(Path("/proc/self/statm").read_text().split()[1]) * 4096 / 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--extra", type=int, default=0, help="other columns logged once before the chunks")
    ap.add_argument(
        "--kind",
        choices=["temporal-components", "static-components", "entities", "timelines"],
        default="temporal-components",
        help="what the extra columns are: a component each (temporal or static), an entity each "
        "(the same component), a timeline each",
    )
    ap.add_argument("--chunks", type=int, default=10000)
    args = ap.parse_args()
    pa.set_memory_pool(pa.system_memory_pool())  # as sins_fw.viewer.recording does
    rec = rr.RecordingStream(
        "footer-memory", recording_id="footer-memory", send_properties=False,
        batcher_config=rr.ChunkBatcherConfig.NEVER(),
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        rec.save(str(Path(tmp) / "f.rrd"), write_footer=True)
        for j in range(args.extra):
            one = [rr.TimeColumn("time", sequence=[1])]
            if args.kind == "temporal-components":
                rec.send_columns(f"x{j}", indexes=one, columns=rr.AnyValues.columns(**{f"c{j}": [1.0]}))
            elif args.kind == "static-components":
                rec.log(f"x{j}", rr.AnyValues(**{f"c{j}": [1.0]}), static=True)
            elif args.kind == "entities":
                rec.send_columns(f"x{j}", indexes=one, columns=rr.Scalars.columns(scalars=[1.0]))
            else:
                own = [rr.TimeColumn(f"t{j}", sequence=[1])]
                rec.send_columns(f"x{j}", indexes=own, columns=rr.Scalars.columns(scalars=[1.0]))
        rec.flush()
        start = rss_mb()
        t = np.arange(100, dtype=np.int64)
        rng = np.random.default_rng(0)
        for i in range(args.chunks):
            at = t + i * 100
            index = [rr.TimeColumn("time", sequence=at), rr.TimeColumn("tick", sequence=at)]
            rec.send_columns(f"e{i % 24}", indexes=index, columns=rr.Scalars.columns(scalars=rng.random(100)))
            if i % 1000 == 999:
                rec.flush()
        rec.flush()
        end = rss_mb()
        rec.disconnect()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3
    print(
        f"extra {args.extra} {args.kind}: {(end - start) * 1e3 / args.chunks:.2f} kB per chunk "
        f"({end - start:.1f} MB over {args.chunks} chunks); peak {peak:.0f} MB, {peak - end:.0f} MB above "
        "the resident memory before the footer was written"
    )


if __name__ == "__main__":
    main()
