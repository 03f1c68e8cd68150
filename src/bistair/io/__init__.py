"""Files: reading captures and specs, atomic output folders, JSON, previews and the writers of
results, point clouds and depth maps. Functions take and return arrays and paths; nothing
here decodes."""
