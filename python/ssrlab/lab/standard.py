"""The standard evaluation (ssrlab bench --suite standard): being written."""


def run_suite(args) -> int:
    raise SystemExit("ssrlab: --suite standard is not available yet")
