"""Report writers: CSV, PNG (matplotlib, Agg), Markdown and JSON, all written atomically."""
