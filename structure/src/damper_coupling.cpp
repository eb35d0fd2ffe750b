// placeholder: filled by the structure issue
