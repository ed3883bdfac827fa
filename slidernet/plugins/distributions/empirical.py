"""Measured thresholds: ``empirical``, the resampling of values read from a file (their ECDF)."""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from slidernet._validation import check_array, is_number_text, read_real
from slidernet.errors import ConfigError, param_error
from slidernet.plugins.distributions.law import Distribution


class Empirical(Distribution):
    """Measured thresholds: resampling of values read from a file (their ECDF).

    ``sample`` draws the values with replacement, uniformly; ``cdf`` is the
    empirical CDF (a step function). Values at or below mu_d are never used:
    slidernet conditions the law on mu_s > mu_d with :class:`TruncatedBelow`
    (rejection), i.e. resamples only the values above mu_d; if every value
    is above mu_d no truncation is needed. mu_max saturates at the largest
    value: E[max of m] = sum_k v_(k) [(k/K)^m - ((k-1)/K)^m] over the K
    sorted values v_(k) above mu_d.

    The file's format, with examples: ``docs/guides/file-formats.md``.

    Parameters
    ----------
    path : str or path-like
        A text file: one value per line, or a CSV table with ``column``.
        Blank lines and lines starting with ``#`` are skipped; a first line
        that is not a number is a header. A relative path is relative to
        the working directory.
    column : int or str, optional
        0-based index or header name of the CSV column to read; without it
        every line must hold a single value.
    delimiter : str
        CSV field separator; default ``","``.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from slidernet.plugins.distributions import TruncatedBelow
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = os.path.join(tmp, "mu_s.csv")
    ...     with open(path, "w") as fh:
    ...         _ = fh.write("sample,mu_s\\na,0.6\\nb,0.7\\nc,0.4\\n")
    ...     d = Empirical(path, column="mu_s")
    >>> d.values.tolist(), float(d.cdf(0.65))
    ([0.4, 0.6, 0.7], 0.6666666666666666)
    >>> round(float(TruncatedBelow(d, lower=0.5, name="empirical").mean_max(2)), 12)  # 0.6 / 4 + 0.7 * 3 / 4
    0.675
    """

    name = "empirical"
    _mu_d_param = "path"

    #: The unit of each parameter, for the configuration reference ("1": dimensionless).
    param_units: ClassVar[dict[str, str]] = {"path": "—", "column": "—", "delimiter": "—"}

    def __init__(self, path: str | os.PathLike, column: int | str | None = None, delimiter: str = ",") -> None:
        if not isinstance(path, (str, os.PathLike)) or not str(path):
            raise param_error("path", "empirical", "the path of a file", path)
        if column is not None and (isinstance(column, bool) or not isinstance(column, (int, str))):
            raise param_error("column", "empirical", "a column index (int) or a header name (str)", column)
        if isinstance(column, int) and column < 0:
            raise param_error("column", "empirical", ">= 0", column)
        if not isinstance(delimiter, str) or len(delimiter) != 1:
            raise param_error("delimiter", "empirical", "a single character", delimiter)
        self.path = str(path)
        self.column = column
        self.delimiter = delimiter
        values = self._read(Path(path))
        self.values = np.sort(values)
        self.values.flags.writeable = False
        self.size = self.values.size

    def _read(self, path: Path) -> np.ndarray:
        if not path.is_file():
            raise param_error("path", "empirical", "an existing file", str(path))
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise param_error("path", "empirical", f"a readable text file ({exc})", str(path)) from None
        lines = [(i, line) for i, line in enumerate(text.splitlines(), 1)
                 if line.strip() and not line.lstrip().startswith("#")]
        index = self.column if isinstance(self.column, int) else 0
        values: list[float] = []
        width = None  # the number of fields of the first line: every line of a table has as many
        for k, (lineno, line) in enumerate(lines):
            row = next(csv.reader([line], delimiter=self.delimiter))
            where = f"{str(path)!r}, line {lineno}"
            width = len(row) if width is None else width
            if len(row) != width:
                raise ConfigError(f"The 'path' parameter of empirical: {where}: {len(row)} fields; the first line "
                                  f"has {width}.")
            if k == 0 and isinstance(self.column, str):
                names = [f.strip() for f in row]
                if self.column not in names:
                    raise param_error("column", "empirical", f"a header name of {where}: {names}", self.column)
                index = names.index(self.column)
                continue
            if self.column is None and len(row) != 1:
                raise ConfigError(f"The 'path' parameter of empirical: {where} has {len(row)} fields; "
                                  "give 'column' to read a CSV table.")
            if index >= len(row):
                raise ConfigError(f"The 'column' parameter of empirical: {where} has no column {index} "
                                  f"(only {len(row)} fields).")
            try:
                values.append(read_real(row[index].strip(), "the value",
                                        f"The 'path' parameter of empirical: {where}"))
            except ConfigError:
                if k == 0 and not is_number_text(row[index]):  # a header
                    continue
                raise
        if len(values) < 2:
            raise param_error("path", "empirical", f"a file with at least 2 values (it has {len(values)})",
                              str(path))
        return np.asarray(values, dtype=float)

    def _params(self) -> dict[str, Any]:
        return {"path": self.path, "column": self.column}

    def support(self) -> tuple[float, float]:
        """(smallest value, largest value)."""
        return float(self.values[0]), float(self.values[-1])

    def check_mu_d(self, mu_d: float) -> None:
        """Refuse data with fewer than 2 values above mu_d, or with less than MIN_MASS of them."""
        above = int(self.size - np.searchsorted(self.values, float(mu_d), side="right"))
        if above < 2:
            raise ConfigError(f"The 'path' parameter of empirical must name a file with at least 2 values "
                              f"> mu_d = {mu_d!r}. Got {self.path!r} instead, with {above} of {self.size}.")
        super().check_mu_d(mu_d)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """``size`` values drawn with replacement, shape ``(size,)``."""
        return self.values[rng.integers(0, self.size, size)]

    def cdf(self, x: ArrayLike) -> np.ndarray:
        """The ECDF: the fraction of values <= x."""
        return np.searchsorted(self.values, np.asarray(x, dtype=float), side="right") / self.size

    def sf(self, x: ArrayLike) -> np.ndarray:
        """The fraction of values > x."""
        below = np.searchsorted(self.values, np.asarray(x, dtype=float), side="right")
        return (self.size - below) / self.size

    def ppf(self, u: ArrayLike) -> np.ndarray:
        """The smallest value v with ECDF(v) >= u."""
        k = np.ceil(np.asarray(u, dtype=float) * self.size).astype(np.intp) - 1
        return self.values[np.clip(k, 0, self.size - 1)]

    def isf(self, q: ArrayLike) -> np.ndarray:
        """The smallest value v with a fraction <= q of values above it."""
        return self.ppf(1.0 - np.asarray(q, dtype=float))

    def mean_max_above(self, m: ArrayLike, lower: float) -> np.ndarray:
        """Exact for the ECDF: sum_k v_(k) [(k/K)^m - ((k-1)/K)^m]; see :meth:`Distribution.mean_max_above`."""
        m_arr = check_array(m, "m", "mean_max", ">= 1")
        v = self.values[self.values > float(lower)]
        if v.size == 0:
            raise param_error("path", self.name, f"a file with values > lower = {lower!r}", self.path)
        k = np.arange(v.size + 1) / v.size
        with np.errstate(divide="ignore"):
            log_k = np.log(k)
        out = np.empty(m_arr.size)
        for i, mi in enumerate(m_arr.ravel()):
            out[i] = np.dot(v, np.diff(np.exp(mi * log_k)))
        return out.reshape(m_arr.shape)
