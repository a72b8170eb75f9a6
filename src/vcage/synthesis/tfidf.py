"""Character n-gram TF-IDF with cosine similarity: robust to misspellings and word forms."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence


class CharTfidf:
    def __init__(self, docs: Sequence[Sequence[str]]) -> None:
        n = len(docs)
        df: Counter[str] = Counter()
        for d in docs:
            df.update(set(d))
        self.idf = {g: math.log((1 + n) / (1 + c)) + 1.0 for g, c in df.items()}
        self.vectors = [self._vector(d) for d in docs]

    def _vector(self, grams: Sequence[str]) -> dict[str, float]:
        tf = Counter(g for g in grams if g in self.idf)
        vec = {g: (1 + math.log(c)) * self.idf[g] for g, c in tf.items()}
        norm = math.sqrt(sum(v * v for v in vec.values())) or 1.0
        return {g: v / norm for g, v in vec.items()}

    def scores(self, grams: Sequence[str]) -> list[float]:
        """Cosine similarity of the query's n-grams with every document (0..1)."""
        q = self._vector(grams)
        return [sum(v * d.get(g, 0.0) for g, v in q.items()) for d in self.vectors]
