"""Slurm array jobs: one task per point (scripts/sweep) or per worker (scripts/explore)."""
import shlex


def array_script(job_name, comments, tasks, log_dir, sbatch, command, tail=""):
    """The text of an sbatch script: `comments` (lines without their '# '), an array of `tasks`
    tasks (one CPU each, logs in log_dir/%A_%a.log), the extra #SBATCH options `sbatch`, then
    `exec` of `command` (a list, quoted here) under $PYTHON (default Debian's) followed by `tail`
    (shell text, e.g. '--point "$SLURM_ARRAY_TASK_ID"') and the script's own arguments."""
    lines = ["#!/bin/bash"] + [f"# {c}" for c in comments]
    lines += [f"#SBATCH --job-name={job_name}",
              f"#SBATCH --array=0-{tasks - 1}",
              "#SBATCH --ntasks=1",
              "#SBATCH --cpus-per-task=1",
              f"#SBATCH --output={log_dir}/%A_%a.log"]
    lines += [f"#SBATCH {o}" for o in sbatch]
    lines += ["set -euo pipefail",
              ': "${SLURM_ARRAY_TASK_ID:?this is a Slurm array job: submit it with sbatch}"',
              'exec "${PYTHON:-/usr/bin/python3}" ' + " ".join(map(shlex.quote, command)) + (f" {tail}" if tail else "")
              + ' "$@"', ""]
    return "\n".join(lines)
