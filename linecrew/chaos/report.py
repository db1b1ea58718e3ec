"""The chaos report: what was injected when, the invariant checks, the
final state of every action, and how to reproduce the run."""

from __future__ import annotations

from linecrew.chaos.runner import ChaosOptions, ChaosResult

INVARIANTS = (
    "action_lost",
    "double_task",
    "below_reserve",
    "unsafe",
    "overcredited",
    "unfinished",
    "failed_without_reason",
)


def render(result: ChaosResult) -> str:
    """The report as plain text."""
    opts, checker = result.options, result.checker
    lines = [
        f"linecrew chaos: seed {opts.seed}, {opts.duration_s:g} s of injections, "
        f"x{opts.speedup:g}, {result.wall_s:.0f} s wall, {result.samples} samples",
        "partitions: "
        + ("real cuts (a network namespace per process)" if opts.netns else "frozen (SIGSTOP)"),
        f"run directory: {result.run_dir}",
        "",
        "injections (wall s since start):",
    ]
    if not result.applied:
        lines.append("  none")
    for applied in result.applied:
        healed = f", healed at {applied.healed_s:.1f}" if applied.healed_s is not None else ""
        note = f" [{applied.note}]" if applied.note else ""
        lines.append(f"  {applied.at_s:6.1f}  {applied.injection.describe()}{healed}{note}")
    lines += ["", "invariants (checks, violations):"]
    broken = {name: 0 for name in INVARIANTS}
    for violation in checker.violations:
        broken[violation.invariant] = broken.get(violation.invariant, 0) + 1
    for name in INVARIANTS:
        lines.append(f"  {name:<22} {checker.checks[name]:>6} {broken[name]:>4}")
    if checker.excused:
        lines += ["", "below reserve, excused by an injected fault (reported):"]
        lines += [f"  {note}" for note in checker.excused]
    if checker.violations:
        lines += ["", "VIOLATIONS:"]
        lines += [f"  t={v.at_s:6.1f} {v.invariant}: {v.detail}" for v in checker.violations]
    lines += ["", "actions at the end:"]
    records = sorted(result.actions or [], key=lambda r: r["action_id"])
    for record in records:
        reason = f"  ({record['reason']})" if record.get("reason") else ""
        lines.append(
            f"  {record['action_id']:<32} {record['state']:<12} "
            f"{100 * record.get('progress', 0):3.0f} %{reason}"
        )
    for action_id, why in sorted(result.rejected.items()):
        lines.append(f"  {action_id:<32} rejected     {why}")
    if result.event_counts:
        counts = ", ".join(f"{k} {v}" for k, v in sorted(result.event_counts.items()))
        lines += ["", f"ground-station events: {counts}"]
    lines += [
        "",
        f"violations: {len(checker.violations)}",
        f"reproduce: {reproduce(opts)}",
    ]
    return "\n".join(lines)


def reproduce(opts: ChaosOptions) -> str:
    """The command line that runs the same schedule on the same kind of fleet."""
    words = ["linecrew chaos", f"--seed {opts.seed}", f"--duration {opts.duration_s:g}"]
    words += [f"--speedup {opts.speedup:g}", f"--drain {opts.drain_s:g}"]
    if not opts.scenario_actions:
        words.append("--no-scenario-actions")
    if opts.netns:
        words.append("--netns")
    return " ".join(words)
