// Reference DEM world (in progress).
