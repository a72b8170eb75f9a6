"""Retrieval of catalog types from paraphrases: Recall@1, Recall@5 and MRR (issue 13, stage 1).

The queries (``benchmarks/data/retrieval_paraphrases.json``, at least 3 hand-written paraphrases
per catalog type) are split *by type* into a tuning half and a test half (a type's half is fixed
by a hash of its name, so adding types moves no other type); the ranker may be tuned on the tuning
half only, and the test half is the figure to report. Negative queries name objects the catalog
lacks and must be answered "no match" (no hits). Types of the catalog without queries, and queries
naming types the catalog lacks, are listed, never silently dropped.

Run from the repository root: ``.venv/bin/python benchmarks/retrieval.py [--verbose]``.
Targets: Recall@5 >= 0.95, Recall@1 >= 0.80 on the test half; every negative answered "no match".
Each query is a phrase naming one object, answered by ``Retriever.find`` (the head-noun rule). The
development negatives were used while developing the ranker; the held-out ones were read in a
report before the head-noun rule was written; the fresh ones were written before that rule and never
tuned on: they are the negatives' figure.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import time
from dataclasses import dataclass
from pathlib import Path

import results
from vcage.assets.catalog import CATALOG
from vcage.synthesis.retrieval import Retriever

DATA = Path(__file__).resolve().parent / "data" / "retrieval_paraphrases.json"
DEPTH = 10  # hits ranked per query; MRR counts a type found deeper than this as 0


def half(type_name: str) -> str:
    """``tune`` or ``test``, fixed by the type's name."""
    return "tune" if hashlib.sha256(type_name.encode()).digest()[0] % 2 == 0 else "test"


@dataclass(frozen=True)
class Scores:
    queries: int
    types: int
    r1: float
    r5: float
    mrr: float
    misses: tuple[tuple[str, str, list[str]], ...]  # (query, expected type, top-3 answer)


def score(retriever: Retriever, items: list[tuple[str, str]]) -> Scores:
    r1 = r5 = rr = 0.0
    misses = []
    for query, want in items:
        names = retriever.find(query, k=DEPTH).names()
        rank = names.index(want) + 1 if want in names else None
        r1 += rank == 1
        r5 += rank is not None and rank <= 5
        rr += 1.0 / rank if rank else 0.0
        if rank != 1:
            misses.append((query, want, names[:3]))
    n = max(1, len(items))
    return Scores(len(items), len({w for _, w in items}), r1 / n, r5 / n, rr / n, tuple(misses))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=DATA)
    parser.add_argument("--verbose", action="store_true", help="list every miss of both halves")
    parser.add_argument("--record", action="store_true", help="write the test half's figures to "
                        "docs/results/retrieval.json (the results page)")
    args = parser.parse_args()
    data = json.loads(args.data.read_text())
    queries: dict[str, list[str]] = data["queries"]
    unknown = sorted(set(queries) - set(CATALOG.names()))
    uncovered = sorted(t for t in CATALOG.names() if len(queries.get(t, [])) < 3)
    retriever = Retriever()
    t0 = time.perf_counter()
    halves = {h: score(retriever, [(q, t) for t, qs in sorted(queries.items())
                                   if t in CATALOG and half(t) == h for q in qs]) for h in ("tune", "test")}
    negatives = [(q, retriever.find(q, k=DEPTH)) for q in data["negatives"]]
    heldout = [(q, retriever.find(q, k=DEPTH)) for q in data.get("negatives_heldout", [])]
    fresh = [(q, retriever.find(q, k=DEPTH)) for q in data.get("negatives_fresh", [])]
    seconds = time.perf_counter() - t0
    print(f"catalog: {len(CATALOG)} types; queries for {len(queries)} types "
          f"({sum(len(v) for v in queries.values())} queries), {len(negatives)} negatives")
    if uncovered:
        print(f"  types with fewer than 3 queries (not measured): {', '.join(uncovered)}")
    if unknown:
        print(f"  query types the catalog lacks (skipped): {', '.join(unknown)}")
    print(f"{'half':6} {'types':>5} {'queries':>7} {'R@1':>6} {'R@5':>6} {'MRR':>6}")
    for name, s in halves.items():
        print(f"{name:6} {s.types:5d} {s.queries:7d} {s.r1:6.3f} {s.r5:6.3f} {s.mrr:6.3f}")
    for label, answers in (("negatives (development)", negatives), ("negatives (held out, seen)", heldout),
                           ("negatives (fresh, never tuned on)", fresh)):
        matched = [f"{q!r} -> {r.best}" for q, r in answers if r.found]
        print(f"{label} answered 'no match': {len(answers) - len(matched)}/{len(answers)}"
              + (f"; matched: {', '.join(matched)}" if matched else ""))
    test = halves["test"]
    asked = test.queries + halves["tune"].queries + len(negatives) + len(heldout) + len(fresh)
    print(f"test half: Recall@1 {test.r1:.3f} (target >= 0.80), Recall@5 {test.r5:.3f} (target >= 0.95), "
          f"MRR {test.mrr:.3f}; {seconds * 1000 / max(1, asked):.1f} ms per query")
    for name, s in halves.items():
        if name == "test" or args.verbose:
            for query, want, got in s.misses:
                print(f"  {name} miss: {query!r} -> {got} (want {want})")
    if args.record:
        no_match = sum(not r.found for _, r in fresh)
        path = results.record(
            "retrieval", "Retrieval of catalog types from paraphrases",
            "Given a phrase naming one object, does the offline retriever answer the catalog type meant "
            "(test half, types whose queries no ranking rule was tuned on), and 'no match' for an object "
            "the catalog lacks (fresh negatives, never tuned on)?",
            {"Recall@1 (test half)": f"{test.r1:.3f}", "Recall@5 (test half)": f"{test.r5:.3f}",
             "MRR (test half)": f"{test.mrr:.3f}",
             "fresh negatives answered 'no match'": f"{no_match}/{len(fresh)}",
             "Recall@1 / Recall@5 (tuning half)": f"{halves['tune'].r1:.3f} / {halves['tune'].r5:.3f}"},
            f"test half: {test.queries} queries for {test.types} types; tuning half: "
            f"{halves['tune'].queries} queries for {halves['tune'].types} types; {len(fresh)} fresh "
            f"negatives; catalog of {len(CATALOG)} types")
        print(f"recorded in {path}")


if __name__ == "__main__":
    main()
