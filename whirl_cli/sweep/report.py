"""A sweep's progress and summary: counts, one line per study, a rich progress bar on a
terminal.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from ..kinds import SweepStatus
from .execute import Outcome


@dataclass
class Tally:
    """Counts of a sweep in progress, for the progress display and the summary."""

    total: int
    started: float = field(default_factory=time.perf_counter)
    outcomes: list[Outcome] = field(default_factory=list)

    @property
    def done(self) -> int:
        return len(self.outcomes)

    @property
    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.failed]

    def count(self, status: SweepStatus) -> int:
        return sum(o.status == status for o in self.outcomes)

    def line(self, outcome: Outcome) -> str:
        """One log line per study: counter, status, name, AUTO time, output or first problem."""
        width = len(str(self.total))
        mark = {SweepStatus.OK: "ok", SweepStatus.SKIPPED: "skip",
                SweepStatus.PLOTTED: "plot"}.get(outcome.status, outcome.status.upper())
        head = f"[{self.done:>{width}}/{self.total}] {mark:<8} {outcome.item.name:<28}"
        if outcome.status == SweepStatus.SKIPPED:
            detail = outcome.item.reason
        elif outcome.status == SweepStatus.PLOTTED:
            detail = f"{outcome.item.reason}: {len(outcome.written)} drawn"
        elif outcome.status in (SweepStatus.OK, SweepStatus.FAILED):
            detail = (f"{outcome.runs:>3} AUTO runs {outcome.auto_seconds:6.2f} s -> "
                      f"{outcome.item.output}")
        else:  # an invalid study's problems name its file
            detail = "" if outcome.status == SweepStatus.INVALID else str(outcome.item.source)
        if outcome.problems:
            more = len(outcome.problems) - 1
            detail += f"  {outcome.problems[0]}" + (f" (+{more} more)" if more else "")
        return f"{head} {detail}"

    def summary(self, interrupted: bool = False) -> str:
        """Counts and elapsed time, then one line per failed study."""
        seconds = time.perf_counter() - self.started
        parts = [f"{self.count(SweepStatus.OK)} ok",
                 f"{self.count(SweepStatus.SKIPPED)} up to date"]
        parts += [f"{n} plots completed" for n in [self.count(SweepStatus.PLOTTED)] if n]
        parts += [f"{n} {s}" for s in (SweepStatus.FAILED, SweepStatus.ERROR,
                                       SweepStatus.INVALID) if (n := self.count(s))]
        if interrupted:
            parts.append(f"{self.total - self.done} not finished (interrupted)")
        text = f"sweep: {', '.join(parts)} of {self.total} studies in {seconds:.1f} s"
        for outcome in self.failures:
            named = "" if outcome.status == SweepStatus.INVALID else f"{outcome.item.source}: "
            text += f"\n  {named}" + "; ".join(outcome.problems)
        return text


class Reporter:
    """Progress of a sweep on stderr: a rich progress bar (done/total, failures, ETA) on a
    terminal, otherwise one plain line per study."""

    def __init__(self, total: int, console=None) -> None:
        from rich.console import Console

        self.console = console or Console(stderr=True, highlight=False)
        self.tally = Tally(total)
        self.progress = None
        self.task = None

    def __enter__(self) -> Reporter:
        if self.console.is_terminal:
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.progress = Progress(
                TextColumn("sweep"), BarColumn(), MofNCompleteColumn(),
                TextColumn("{task.fields[failed]} failed"), TimeElapsedColumn(),
                TextColumn("ETA"), TimeRemainingColumn(), console=self.console)
            self.progress.start()
            self.task = self.progress.add_task("sweep", total=self.tally.total, failed=0)
        return self

    def __exit__(self, *exc) -> None:
        if self.progress is not None:
            self.progress.stop()

    def __call__(self, outcome: Outcome) -> None:
        self.tally.outcomes.append(outcome)
        line = self.tally.line(outcome)
        if self.progress is not None:
            self.progress.console.print(line, markup=False, soft_wrap=True)
            self.progress.update(self.task, completed=self.tally.done,
                                 failed=len(self.tally.failures))
        else:
            self.console.print(line, markup=False, soft_wrap=True)

