"""Okapi BM25 over token lists, with the IDF that never goes negative.

``idf(t) = ln(1 + (N - df + 0.5) / (df + 0.5))`` (Lucene's form): a word in most documents weighs
little but never counts against a document, as the original ``ln((N - df + 0.5) / (df + 0.5))``
would for a word in more than half of them.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence


class BM25:
    def __init__(self, docs: Sequence[Sequence[str]], k1: float = 1.2, b: float = 0.75) -> None:
        if not docs:
            raise ValueError("BM25 needs at least one document")
        self.k1, self.b = k1, b
        self.tf = [Counter(d) for d in docs]
        self.len = [len(d) for d in docs]
        self.avg = sum(self.len) / len(docs) or 1.0
        df: Counter[str] = Counter()
        for tf in self.tf:
            df.update(tf.keys())
        n = len(docs)
        self.idf = {t: math.log(1.0 + (n - c + 0.5) / (c + 0.5)) for t, c in df.items()}

    @property
    def vocabulary(self) -> frozenset[str]:
        return frozenset(self.idf)

    def scores(self, query: Mapping[str, float]) -> list[float]:
        """Score of every document for weighted query tokens (weight multiplies a token's term)."""
        out = []
        for tf, length in zip(self.tf, self.len, strict=True):
            norm = self.k1 * (1 - self.b + self.b * length / self.avg)
            s = 0.0
            for tok, w in query.items():
                f = tf.get(tok, 0)
                if f:
                    s += w * self.idf[tok] * f * (self.k1 + 1) / (f + norm)
            out.append(s)
        return out
