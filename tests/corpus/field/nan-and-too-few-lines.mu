# mu frame=global faces=16
nan nan
1e308 0
