"""Run many ``colregs9`` command lines in one Python process, each as the console script
would (Typer in standalone mode), and record for each its exit code, stdout and stderr, and
any exception that escaped (a traceback the user would see).

Usage: ``python tests/cli_driver.py CASES.json RESULTS.json``; CASES.json is a list of
``{"id": ..., "args": [...], "cwd": ...}``. Python warnings are shown every time (not once
per place) and land in the captured stderr, as they would on the user's terminal.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import sys
import traceback
import warnings


def run_case(args: list[str], cwd: str) -> dict[str, object]:
    from colregs9_cli.cli import app

    stdout, stderr = io.StringIO(), io.StringIO()
    code: object = 0
    escaped = None
    previous = os.getcwd()
    os.chdir(cwd)
    try:
        with (
            contextlib.redirect_stdout(stdout),
            contextlib.redirect_stderr(stderr),
            warnings.catch_warnings(),
        ):
            warnings.simplefilter("always")
            try:
                app(args=args, prog_name="colregs9", standalone_mode=True)
            except SystemExit as exc:
                code = exc.code if exc.code is not None else 0
            except BaseException:
                escaped = traceback.format_exc()
                code = 1
    finally:
        os.chdir(previous)
    return {
        "code": code,
        "stdout": stdout.getvalue(),
        "stderr": stderr.getvalue(),
        "escaped": escaped,
    }


def main() -> None:
    cases_path, results_path = sys.argv[1], sys.argv[2]
    with open(cases_path, encoding="utf-8") as handle:
        cases = json.load(handle)
    results = {case["id"]: run_case(case["args"], case["cwd"]) for case in cases}
    with open(results_path, "w", encoding="utf-8") as handle:
        json.dump(results, handle)


if __name__ == "__main__":
    main()
