"""AIS ingest: readers for each layout, the canonical schema, cleaning and the rejects ledger."""
