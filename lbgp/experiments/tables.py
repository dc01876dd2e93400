"""Markdown and CSV tables of experiment results beside the paper's numbers."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

from lbgp.files import write_text
from lbgp.metrics import reward_ci95

METHOD_NAMES = {"lbgp": "LBGP", "hc": "HC", "e2e": "E2E"}


TIE = "tie"


def winner(rewards: dict, ci95: dict | None = None) -> str:
    """The method with the highest reward (None and NaN never win). With confidence intervals
    (``ci95[m]``: half-width of the 95 % interval of the mean), a method wins only where its interval
    lies wholly above every other method's; otherwise the row is a ``tie``."""
    valid = {m: r for m, r in rewards.items() if r is not None and not math.isnan(r)}
    if not valid:
        return ""
    best = max(valid, key=valid.get)
    if ci95 is None:
        return best
    half = {m: ci95.get(m, math.nan) for m in valid}
    if any(math.isnan(h) for h in half.values()):
        return TIE  # fewer than two episodes: no ranking
    low = valid[best] - half[best]
    return best if all(low > valid[m] + half[m] for m in valid if m != best) else TIE


def head_to_head(rows: list[dict], group_keys: list[str], a: str = "lbgp", b: str = "hc") -> dict | None:
    """Method ``a`` against ``b`` over the groups that have both: in how many its reward is higher or
    lower with the 95 % intervals separated, in how many they overlap, and in how many its mean is at
    least ``b``'s. ``rows`` as ``write_tables`` takes them (or read back from its CSV). None when no
    group has both."""
    groups: dict = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in group_keys), {})[r["method"]] = (float(r["reward"]), float(r.get("reward_ci95", math.nan)))
    pairs = [(m[a], m[b]) for m in groups.values() if a in m and b in m]
    if not pairs:
        return None
    higher = sum(1 for (ra, ca), (rb, cb) in pairs if ra - ca > rb + cb)
    lower = sum(1 for (ra, ca), (rb, cb) in pairs if rb - cb > ra + ca)
    return {"rows": len(pairs), "higher": higher, "lower": lower, "overlap": len(pairs) - higher - lower,
            "mean_at_least": sum(1 for (ra, _), (rb, _) in pairs if ra >= rb)}


def paired_lead(rows: list[dict], groups: list, a: str = "lbgp", b: str = "hc", group_key: str = "scenario") -> dict:
    """Method ``a``'s reward minus ``b``'s summed over the rows ``groups`` (values of ``group_key``),
    with the half-width of its 95 % interval, paired by episode: the rows' episodes are seeded alike
    for every method (``lbgp.evaluate``), so episode i's lead is the sum over the rows of a's minus
    b's return in their i-th episodes, and the sum of the rows' mean leads is the mean of those. Needs
    ``episode_rewards`` in the rows and the same number of episodes in each; raises ValueError
    naming what is missing."""
    by_key = {(r[group_key], r["method"]): r for r in rows}
    leads = None
    for group in groups:
        pair = []
        for method in (a, b):
            row = by_key.get((group, method))
            if row is None or "episode_rewards" not in row:
                raise ValueError(f"paired lead: no episode rewards of {method} on {group}")
            pair.append(np.asarray(row["episode_rewards"], dtype=float))
        if pair[0].shape != pair[1].shape or (leads is not None and leads.shape != pair[0].shape):
            raise ValueError(f"paired lead: {group} has {pair[0].size} and {pair[1].size} episodes, the other rows {None if leads is None else leads.size}: "
                             "pairing needs the same episodes everywhere")
        leads = pair[0] - pair[1] if leads is None else leads + pair[0] - pair[1]
    if leads is None:
        raise ValueError("paired lead: no rows named")
    return {"lead": float(leads.mean()), "ci95": reward_ci95(leads), "episodes": int(leads.size)}


def head_to_head_csv(path, a: str = "lbgp", b: str = "hc") -> dict | None:
    """``head_to_head`` of a table's CSV (``results/sim_table.csv``, ``results/real_protocol*_table.csv``)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    group_keys = [k for k in rows[0] if k in ("scenario", "path", "setting")] if rows else []
    return head_to_head(rows, group_keys, a, b)


def _fmt_ours(row: dict) -> tuple[str, str, str]:
    ci = row.get("reward_ci95", math.nan)
    reward = f"{row['reward']:.2f}" + (f" ± {ci:.2f}" if not math.isnan(ci) else "")
    return (f"{row['distance_mean']:.2f} ± {row['distance_std']:.2f}", f"{row['alpha_mean_deg']:.1f} ± {row['alpha_std_deg']:.1f}",
            reward)


def _fmt_paper(p) -> tuple[str, str, str]:
    if p is None:
        return "Failed", "Failed", "Failed"
    return f"{p[0]:.2f} ± {p[1]:.1f}", f"{p[2]:.1f} ± {p[3]:.1f}", f"{p[4]:.2f}"


def write_tables(rows: list[dict], group_keys: list[str], paper: dict, out_md: Path, out_csv: Path, title: str, preamble: str,
                 ceilings: dict | None = None, leads: dict | None = None) -> None:
    """``rows``: one dict per (group, method) with the evaluation keys; ``paper[group][method]``
    the paper's tuple (or None = failed). Winner per group by our reward, only where the 95 %
    intervals separate (else "tie"), and by the paper's. ``ceilings[group]``: the reward ceiling,
    shown with each method's share of it. ``leads[name]``: groups (one key) over which LBGP's lead
    over HC is summed and reported with its paired interval (``paired_lead``), where both ran them."""
    ceilings = ceilings or {}
    groups: dict = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in group_keys), {})[r["method"]] = r
    md = io.StringIO()
    md.write(f"# {title}\n\n{preamble}\n\n")
    md.write(f"| {' | '.join(group_keys)} | method | D ours | alpha ours (deg) | reward ours (mean ± 95 % CI) | share of ceiling | "
             "collisions / early ends | D paper | alpha paper | reward paper |\n")
    md.write("|" + "---|" * (len(group_keys) + 9) + "\n")
    summary = []
    csv_rows = []
    for key, by_method in groups.items():
        paper_group = paper.get(key if len(key) > 1 else key[0], {})
        ours_best = winner({m: r["reward"] for m, r in by_method.items()}, {m: r.get("reward_ci95", math.nan) for m, r in by_method.items()})
        ceiling = ceilings.get(key if len(key) > 1 else key[0])
        paper_best = winner({m: (p[4] if p else None) for m, p in paper_group.items()})
        for method, r in by_method.items():
            d, a, rew = _fmt_ours(r)
            pd, pa, prew = _fmt_paper(paper_group.get(method)) if method in paper_group else ("", "", "")
            bold = (lambda s, m=method, b=ours_best: f"**{s}**" if m == b else s)
            pbold = (lambda s, m=method, b=paper_best: f"**{s}**" if m == b and s not in ("", "Failed") else s)
            share = f"{r['reward'] / ceiling:.0%} of {ceiling:.1f}" if ceiling else ""
            md.write(f"| {' | '.join(map(str, key))} | {METHOD_NAMES.get(method, method)} | {d} | {a} | {bold(rew)} | {share} | "
                     f"{r['collisions']} / {r['terminated_early']} | {pd} | {pa} | {pbold(prew)} |\n")
            p = paper_group.get(method)
            csv_rows.append({**{k: v for k, v in zip(group_keys, key)}, "method": method,
                             **{k: r.get(k, "") for k in ("distance_mean", "distance_std", "alpha_mean_deg", "alpha_std_deg", "reward",
                                                          "reward_std", "reward_ci95", "collisions", "terminated_early", "loops",
                                                          "steps", "episodes")},
                             "ceiling": ceiling if ceiling else "",
                             "paper_distance_mean": p[0] if p else "", "paper_alpha_mean_deg": p[2] if p else "",
                             "paper_reward": p[4] if p else ("failed" if method in paper_group else ""),
                             "winner_ours": ours_best, "winner_paper": paper_best})
        summary.append((key, ours_best, paper_best))
    md.write("\n## Winner per row (by accumulated reward; ours only where the 95 % intervals separate)\n\n| " + " | ".join(group_keys) + " | ours | paper |\n|"
             + "---|" * (len(group_keys) + 2) + "\n")
    for key, ours_best, paper_best in summary:
        md.write(f"| {' | '.join(map(str, key))} | {METHOD_NAMES.get(ours_best, ours_best)} | {METHOD_NAMES.get(paper_best, paper_best)} |\n")
    lbgp_wins = sum(1 for _, o, _ in summary if o == "lbgp")
    ties = sum(1 for _, o, _ in summary if o == TIE)
    md.write(f"\nLBGP wins {lbgp_wins} of {len(summary)} rows here, {ties} {'is a tie' if ties == 1 else 'are ties'} (the paper: "
             f"{sum(1 for _, _, p in summary if p == 'lbgp')} of {len(summary)}).\n")
    h2h = head_to_head(rows, group_keys)
    if h2h is not None:
        md.write(f"\nLBGP against HC (the learned goal against the hand-crafted one, the same planner): higher in "
                 f"{h2h['higher']} and lower in {h2h['lower']} of {h2h['rows']} rows with the 95 % intervals separated, "
                 f"overlapping in {h2h['overlap']}; the higher or equal mean in {h2h['mean_at_least']}.\n")
    methods = {r["method"] for r in rows}
    present = {r[group_keys[0]] for r in rows}
    for name, members in (leads or {}).items():
        if {"lbgp", "hc"} <= methods and set(members) <= present:
            lead = paired_lead(rows, members, group_key=group_keys[0])
            md.write(f"\nLBGP - HC summed over the {name} rows ({', '.join(members)}): {lead['lead']:+.2f} ± {lead['ci95']:.2f} "
                     f"(95 % interval, paired by episode over {lead['episodes']} seeds).\n")
    write_text(out_md, md.getvalue())
    buf = io.StringIO()
    if csv_rows:
        w = csv.DictWriter(buf, fieldnames=list(csv_rows[0]))
        w.writeheader()
        w.writerows(csv_rows)
    write_text(out_csv, buf.getvalue())

