// placeholder: the GL driver is being written
